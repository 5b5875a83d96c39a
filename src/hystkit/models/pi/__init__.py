"""Kuhnen's modified Prandtl-Ishlinskii model with creep, sec. 2.1.6 (docs/models/pi.md).

``model`` holds the equations, the analytical inverse (eq. 2.19) and the readable reference,
``kernels`` the compiled loops, ``fit`` the identification (Kuhnen's generalised error, one
bounded linear least-squares solve), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .family import PiFamily

FAMILY = PiFamily()

# The model's equations, its fit and its numba kernels load when one of their names is first
# used, so that the registry (hystkit fit --help) lists the family without compiling anything.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"model": ("*",), "fit": ("*",)},
    first=("FAMILY", "PiFamily"))
