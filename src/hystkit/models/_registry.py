"""Where model families are found: the folders of this package, plugins, and ``register``.

A family is a sub-package ``hystkit/models/<folder>/``: its ``__init__`` declares ``INFO``, a
:class:`FamilyInfo` (name, title, sizes, docs), and its ``family.py`` exports ``FAMILY``, which
imports the folder's model and kernels at top level like ordinary code. The laziness is here:
the registry reads a folder's light ``INFO`` and imports its ``family.py`` only when the family
object itself is asked for (:func:`get_family`, ``FAMILIES[name]``), so listing the families or
showing their help (:data:`FAMILY_INFO`, :func:`family_info`) loads no numba or scipy. Before
anything is discovered or registered, looking up one name imports only its own folder (``fit
--model mpl`` reads no other family and no entry points).

A separately installed package adds a family through the ``hystkit.families`` entry-point group
(the value names a module exporting ``FAMILY``); code (a test, a notebook) calls
:func:`register`.
"""

from __future__ import annotations

import importlib
import importlib.util
import pkgutil
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from importlib.metadata import entry_points

from .._docfill import docfiller
from ..errors import InputError
from ._protocol import Family, FamilyInfo

__all__ = ["FAMILIES", "FAMILY_INFO", "family_info", "family_of", "get_family", "register",
           "unregister"]

# The Parameters section of the look-ups by family name (%(family_name)s).
REGISTRY_ENTRIES = {
    "family_name": """Parameters
----------
name : str
    Family name (``"mpl"``, ``"preisach"``, ...).""",
}
fill_registry_doc = docfiller(REGISTRY_ENTRIES.__getitem__)

_PACKAGE = __name__.rpartition(".")[0]


@dataclass
class _Entry:
    """One registered family: its record, and the module whose ``FAMILY`` it is."""

    info: FamilyInfo
    source: str
    family: Family | None = None

    def load(self) -> Family:
        if self.family is None:
            family = _check(importlib.import_module(self.source).FAMILY, self.source)
            if FamilyInfo.of(family) != self.info or family.has_inverse != self.info.has_inverse:
                raise TypeError(f"{self.source}: FAMILY does not match the INFO its folder "
                                f"declares ({FamilyInfo.of(family)} != {self.info})")
            self.family = family
        return self.family


_found: dict[str, _Entry] | None = None
# Families looked up by name before discovery (``_own_folder``), kept so that the next lookup
# (``Compensator.family``, asked per call) is a dict read, not a module search (3.9 -> 0.13 us).
_own: dict[str, _Entry | None] = {}


def _check(family: object, origin: str) -> Family:
    if not isinstance(family, Family):
        raise TypeError(f"{origin}: FAMILY must be an instance of hystkit.models.Family, got "
                        f"{type(family).__name__}")
    return family


def _folder(folder: str) -> _Entry | None:
    """The family of sub-package `folder` from its ``INFO``; None for a folder without one."""
    module = importlib.import_module(f"{_PACKAGE}.{folder}")
    info = getattr(module, "INFO", None)
    if info is None:
        return None
    if not isinstance(info, FamilyInfo):
        raise TypeError(f"{module.__name__}: INFO must be a hystkit.models.FamilyInfo, got "
                        f"{type(info).__name__}")
    return _Entry(info, f"{module.__name__}.family")


def _discover() -> dict[str, _Entry]:
    entries: dict[str, _Entry] = {}
    package = importlib.import_module(_PACKAGE)
    for module in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
        entry = _folder(module.name) if module.ispkg else None
        if entry is not None:
            entries[entry.info.name] = entry
    for point in entry_points(group="hystkit.families"):
        family = _check(point.load().FAMILY, f"entry point {point.name}")
        entries.setdefault(family.name, _Entry(FamilyInfo.of(family), point.value, family))
    return entries


def _entries() -> dict[str, _Entry]:
    global _found
    if _found is None:
        _found = _discover()
    return _found


def _own_folder(name: str) -> _Entry | None:
    """The family `name` from its own folder (``mpl-g``: ``mpl_g``) before any discovery, or
    None. Discovery gives a folder's family precedence over plugins, so this is the family it
    would find."""
    if _found is not None:
        return None
    if name not in _own:
        _own[name] = _search_own_folder(name)
    return _own[name]


def _search_own_folder(name: str) -> _Entry | None:
    folder = name.replace("-", "_")
    if not folder.isidentifier() or folder.startswith("_"):
        return None
    spec = importlib.util.find_spec(f"{_PACKAGE}.{folder}")
    if spec is None or spec.submodule_search_locations is None:  # not a sub-package
        return None
    entry = _folder(folder)
    return entry if entry is not None and entry.info.name == name else None


def _lookup(name: str) -> _Entry | None:
    return _own_folder(name) or _entries().get(name)


def _entry(name: str) -> _Entry:
    entry = _lookup(name)
    if entry is None:
        raise InputError(f"unknown model {name!r}; known models: "
                         f"{', '.join(sorted(_entries()))}")
    return entry


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
    _check(family, "register")
    _entries()[family.name] = _Entry(FamilyInfo.of(family), type(family).__module__, family)
    return family


def unregister(name: str) -> None:
    """Remove a family added by :func:`register` (tests clean up with it).

    Parameters
    ----------
    name : str
        Family name; a name not registered is ignored.
    """
    _entries().pop(name, None)


@fill_registry_doc
def get_family(name: str) -> Family:
    """The registered family ``name`` (its ``family.py`` imported on first use); InputError
    listing the known ones otherwise.

    %(family_name)s

    Returns
    -------
    Family
        The registered family.

    Raises
    ------
    InputError
        An unknown name.
    """
    return _entry(name).load()


@fill_registry_doc
def family_info(name: str) -> FamilyInfo:
    """What the registry knows of family ``name`` without loading its code.

    %(family_name)s

    Returns
    -------
    FamilyInfo
        Its name, title, sizes, docs page and whether it has an inverse.

    Raises
    ------
    InputError
        An unknown name.
    """
    return _entry(name).info


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
    module = type(structure).__module__
    # the family whose folder defines the class first: the other families stay unloaded
    entries = sorted(_entries().values(),
                     key=lambda e: not module.startswith(e.source.rpartition(".")[0] + "."))
    for entry in entries:
        family = entry.load()
        if isinstance(structure, family.Structure):
            return family
    raise TypeError(f"{type(structure).__name__} is not the structure of a registered model "
                    f"family")


class _Registry(Mapping):
    """Read-only, lazily discovered view of the registry, sorted by name: the families
    (``FAMILIES``, loading each on first use) or their records (``FAMILY_INFO``)."""

    def __init__(self, loaded: bool) -> None:
        self._loaded = loaded

    def __getitem__(self, name: str):
        entry = _lookup(name) if isinstance(name, str) else None
        if entry is None:
            raise KeyError(name)
        return entry.load() if self._loaded else entry.info

    def __contains__(self, name: object) -> bool:  # a name check loads no family
        return isinstance(name, str) and _lookup(name) is not None

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(_entries()))

    def __len__(self) -> int:
        return len(_entries())

    def __repr__(self) -> str:
        return f"{'FAMILIES' if self._loaded else 'FAMILY_INFO'}({', '.join(self)})"


FAMILIES: Mapping[str, Family] = _Registry(loaded=True)
FAMILY_INFO: Mapping[str, FamilyInfo] = _Registry(loaded=False)
