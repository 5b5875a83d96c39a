"""Deferred imports, so that ``import hystkit`` and listing the model families stay instant.

:func:`lazy_exports` gives a package a PEP 562 ``__getattr__`` that imports a public name's
submodule when the name is first used (``hystkit`` and its sub-packages, the family folders,
whose ``__init__`` holds only the light ``INFO`` the registry reads; see
:mod:`hystkit.models._registry`).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping

__all__ = ["lazy_exports"]


def lazy_exports(package: str, namespace: dict[str, object],
                 exports: Mapping[str, tuple[str, ...]], first: tuple[str, ...],
                 ) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """Module ``__getattr__`` and ``__dir__`` (PEP 562) for a package with deferred names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    namespace : dict
        The package's ``globals()``; a resolved name is stored there, so it is looked up once.
    exports : mapping
        Submodule (relative, e.g. ``"model"``) -> the public names taken from it, where ``"*"``
        stands for the submodule's own ``__all__``. Every submodule is also reachable as an
        attribute (``hystkit.models.mpl.kernels``).
    first : tuple of str
        Names that lead ``__all__``: those the package defines itself (``FAMILY``, the family
        class) and any submodule it lists as public.

    Returns
    -------
    (__getattr__, __dir__)
    """

    def names_of(submodule: str) -> tuple[str, ...]:
        listed = tuple(n for n in exports[submodule] if n != "*")
        if "*" in exports[submodule]:
            listed += tuple(importlib.import_module(f"{package}.{submodule}").__all__)
        return listed

    def public() -> list[str]:
        return list(first) + [n for sub in exports for n in names_of(sub)]

    def getattr_(name: str) -> object:
        if name == "__all__":
            value: object = public()
        elif name.startswith("__"):
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        else:
            value = _resolve(package, exports, names_of, name)
        namespace[name] = value
        return value

    def dir_() -> list[str]:
        return sorted(set(namespace) | set(public()) | set(exports))

    return getattr_, dir_


def _resolve(package: str, exports: Mapping[str, tuple[str, ...]],
             names_of: Callable[[str], tuple[str, ...]], name: str) -> object:
    for submodule, listed in exports.items():  # named exports first: no import to decide
        if name in listed:
            return getattr(importlib.import_module(f"{package}.{submodule}"), name)
    try:
        return importlib.import_module(f"{package}.{name}")  # a submodule (model, kernels, ...)
    except ModuleNotFoundError as exc:
        if exc.name != f"{package}.{name}":
            raise
    for submodule, listed in exports.items():
        if "*" in listed and name in names_of(submodule):
            return getattr(importlib.import_module(f"{package}.{submodule}"), name)
    raise AttributeError(f"module {package!r} has no attribute {name!r}")
