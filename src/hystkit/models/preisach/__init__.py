"""Classical Preisach model, sec. 2.1.1 and appendix 9.3-9.5 (docs/models/preisach.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops
(shared with the generalised model, ``models/gpreisach``), ``fit`` the identification (least
squares and FORCs), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .family import PreisachFamily
from .family import StaircaseFamily as StaircaseFamily

FAMILY = PreisachFamily()

# The model's equations, its fit and its numba kernels load when one of their names is first
# used, so that the registry (hystkit fit --help) lists the family without compiling anything.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"model": ("*", "INVERT_TOL"), "fit": ("*",)},
    first=("FAMILY", "PreisachFamily", "StaircaseFamily", "kernels"))
