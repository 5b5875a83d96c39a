"""Classical Preisach model, sec. 2.1.1 and appendix 9.3-9.5 (docs/models/preisach.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops
(shared with the generalised model, ``models/gpreisach``), ``fit`` the identification (least
squares and FORCs), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="preisach", docs="docs/models/preisach.md", default_size=20, max_size=100,
    title="classical Preisach, Everett function on a grid (sec. 2.1.1, eq. 2.1, 9.4-9.13)",
    size_help="grid levels L over the normalised input (L (L - 1) / 2 Preisach cells)")

__getattr__, __dir__ = family_exports(
    __name__, globals(), "PreisachFamily", "StaircaseFamily",
    first=("kernels",), model=("*", "INVERT_TOL"))
