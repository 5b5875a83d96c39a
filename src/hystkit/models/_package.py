"""The names a family folder's ``__init__`` exports, loaded when first used.

The registry reads a folder's ``INFO`` (``hystkit fit --help`` loads no model); the family
object (``FAMILY``), its equations, fit and numba kernels load when one of their names is first
used (:func:`hystkit._lazy.lazy_exports`).
"""

from __future__ import annotations

from collections.abc import Callable

from .._lazy import lazy_exports

__all__ = ["family_exports"]


def family_exports(package: str, namespace: dict[str, object], *family_names: str,
                   first: tuple[str, ...] = (), **exports: tuple[str, ...],
                   ) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` of a family folder: ``FAMILY`` and `family_names` from
    ``family.py``, the ``__all__`` of ``model`` and ``fit`` unless `exports` names other names
    (or other submodules), after ``INFO`` and `first`."""
    names = {"family": ("FAMILY", *family_names), "model": ("*",), "fit": ("*",), **exports}
    return lazy_exports(package, namespace, names, first=("INFO", *first))
