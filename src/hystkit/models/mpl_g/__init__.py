"""The ch. 7 compensator: sinh cells with a cubic output resistor g (sec. 7.2;
docs/models/mpl_g.md).

``model`` holds the equations, inverse and readable reference, ``kernels`` the compiled loops
(with the loop blocks), ``fit`` the identification, ``presets`` the sec. 7.2 compensators of
paper 9.2's table II sensors, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .family import MplGFamily

FAMILY = MplGFamily()

# The model's equations, its fit and its numba kernels load when one of their names is first
# used, so that the registry (hystkit fit --help) lists the family without compiling anything.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"model": ("*",), "fit": ("canonical", "fit_mpl_g"),
     "presets": ("ch7_compensator", "table_ii_response")},
    first=("FAMILY", "MplGFamily"))
