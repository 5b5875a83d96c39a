"""Chua-Stromsmoe model, sec. 2.1.3 of the reference document (docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="chua",
    title="Chua-Stromsmoe, dy/dt = g(u - f(y)) (sec. 2.1.3, eq. 2.3)",
    size_help="elements in series N, output the sum of their states (6N params; 1 = eq. 2.3)",
    default_size=1,
    max_size=20,
    docs="docs/models/circuits.md")

# The registry reads INFO (hystkit fit --help loads no model); the family object (FAMILY), its
# equations, fit and numba kernels load when one of their names is first used.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"family": ("FAMILY", "ChuaFamily"), "model": ("*",), "fit": ("*",)},
    first=("INFO",))
