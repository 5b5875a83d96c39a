"""Kuhnen's modified Prandtl-Ishlinskii model with creep, sec. 2.1.6 (docs/models/pi.md).

``model`` holds the equations, the analytical inverse (eq. 2.19) and the readable reference,
``kernels`` the compiled loops, ``fit`` the identification (Kuhnen's generalised error, one
bounded linear least-squares solve), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="pi",
    title="Kuhnen / modified Prandtl-Ishlinskii with creep (sec. 2.1.6, eq. 2.6-2.19)",
    size_help="play operators n (thresholds i/n, i < n; plus 2 x 2 dead zones, 4 creep operators "
              "by default)",
    default_size=10,
    max_size=200,
    docs="docs/models/pi.md")

# The registry reads INFO (hystkit fit --help loads no model); the family object (FAMILY), its
# equations, fit and numba kernels load when one of their names is first used.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"family": ("FAMILY", "PiFamily"), "model": ("*",), "fit": ("*",)},
    first=("INFO",))
