"""Bobbio-Marrucci spring/piston chain, sec. 2.1.4 of the reference document
(docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .family import BobbioFamily

FAMILY = BobbioFamily()

# The model's equations, its fit and its numba kernels load when one of their names is first
# used, so that the registry (hystkit fit --help) lists the family without compiling anything.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"model": ("*",), "fit": ("*",)},
    first=("FAMILY", "BobbioFamily"))
