"""Where model families are found: the folders of this package, plugins, and ``register``.

A family is a sub-package ``hystkit/models/<folder>/`` exporting ``FAMILY``; a separately
installed package can add one through the ``hystkit.families`` entry-point group (the value
names a module exporting ``FAMILY``); code (a test, a notebook) can call :func:`register`.
Discovery is lazy, so commands that never touch a model do not import any, and looking up one
name (``get_family``, ``name in FAMILIES``) imports only its own folder while nothing has been
discovered or registered yet.
"""

from __future__ import annotations

import importlib
import importlib.util
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


def _own_folder(name: str) -> Family | None:
    """The family `name` from its own folder (``mpl-g``: ``mpl_g``) before any discovery, or
    None. Discovery gives a folder's family precedence over plugins, so this is the family it
    would find; a command naming one model imports no other (~8 ms less, the entry points
    unread)."""
    folder = name.replace("-", "_")
    if _found is not None or not folder.isidentifier() or folder.startswith("_"):
        return None
    spec = importlib.util.find_spec(f"{_PACKAGE}.{folder}")
    if spec is None or spec.submodule_search_locations is None:  # not a sub-package
        return None
    module = importlib.import_module(spec.name)
    family = getattr(module, "FAMILY", None)
    if family is None or _check(family, module.__name__).name != name:
        return None
    return family


def _lookup(name: str) -> Family | None:
    return _own_folder(name) or _families().get(name)


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
    family = _lookup(name)
    if family is None:
        raise InputError(f"unknown model {name!r}; known models: "
                         f"{', '.join(sorted(_families()))}")
    return family


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
        family = _lookup(name) if isinstance(name, str) else None
        if family is None:
            raise KeyError(name)
        return family

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(_families()))

    def __len__(self) -> int:
        return len(_families())

    def __repr__(self) -> str:
        return f"FAMILIES({', '.join(self)})"


FAMILIES: Mapping[str, Family] = _Families()
