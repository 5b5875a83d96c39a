"""Where model families are found: the folders of this package, plugins, and ``register``.

A family is a sub-package ``hystkit/models/<folder>/`` exporting ``FAMILY``; a separately
installed package can add one through the ``hystkit.families`` entry-point group (the value
names a module exporting ``FAMILY``); code (a test, a notebook) can call :func:`register`.
Discovery is lazy, so commands that never touch a model do not import any.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Iterator, Mapping
from importlib.metadata import entry_points

from ..errors import InputError
from ._protocol import Family

__all__ = ["FAMILIES", "family_of", "get_family", "register", "unregister"]

_PACKAGE = __name__.rpartition(".")[0]
_found: dict[str, Family] | None = None


def _check(family: object, origin: str) -> Family:
    if not isinstance(family, Family):
        raise TypeError(f"{origin}: FAMILY must be an instance of hystkit.models.Family, got "
                        f"{type(family).__name__}")
    return family


def _discover() -> dict[str, Family]:
    families: dict[str, Family] = {}
    package = importlib.import_module(_PACKAGE)
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
        if info.ispkg:
            module = importlib.import_module(f"{_PACKAGE}.{info.name}")
            if hasattr(module, "FAMILY"):
                family = _check(module.FAMILY, module.__name__)
                families[family.name] = family
    for point in entry_points(group="hystkit.families"):
        family = _check(point.load().FAMILY, f"entry point {point.name}")
        families.setdefault(family.name, family)
    return families


def _families() -> dict[str, Family]:
    global _found
    if _found is None:
        _found = _discover()
    return _found


def register(family: Family) -> Family:
    """Add ``family`` to the registry (replacing one of the same name); returns it.

    Parameters
    ----------
    family : Family
        The family to add.

    Returns
    -------
    Family
        `family`, so that it can be used as ``FAMILY = register(Family(...))``.

    Raises
    ------
    TypeError
        `family` is not a :class:`Family`.
    """
    _families()[_check(family, "register").name] = family
    return family


def unregister(name: str) -> None:
    """Remove a family added by :func:`register` (tests clean up with it).

    Parameters
    ----------
    name : str
        Family name; a name not registered is ignored.
    """
    _families().pop(name, None)


def get_family(name: str) -> Family:
    """The registered family ``name``; InputError listing the known ones otherwise.

    Parameters
    ----------
    name : str
        Family name (``"mpl"``, ``"preisach"``, ...).

    Returns
    -------
    Family
        The registered family.

    Raises
    ------
    InputError
        An unknown name.
    """
    families = _families()
    try:
        return families[name]
    except KeyError:
        raise InputError(f"unknown model {name!r}; known models: "
                         f"{', '.join(sorted(families))}") from None


def family_of(structure: object) -> Family:
    """The registered family whose ``Structure`` ``structure`` is; TypeError otherwise.

    Parameters
    ----------
    structure : object
        A family's ``Structure`` instance.

    Returns
    -------
    Family
        The family it belongs to.

    Raises
    ------
    TypeError
        `structure` belongs to no registered family.
    """
    for family in _families().values():
        if isinstance(structure, family.Structure):
            return family
    raise TypeError(f"{type(structure).__name__} is not the structure of a registered model "
                    f"family")


class _Families(Mapping[str, Family]):
    """Read-only, lazily discovered view of the registry, sorted by name."""

    def __getitem__(self, name: str) -> Family:
        return _families()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(_families()))

    def __len__(self) -> int:
        return len(_families())

    def __repr__(self) -> str:
        return f"FAMILIES({', '.join(self)})"


FAMILIES: Mapping[str, Family] = _Families()
