"""Generalised (non-linear) Preisach model of Mayergoyz and Friedman, sec. 2.1.2, eq. 2.2
(docs/models/preisach.md).

It extends the classical model (``hystkit.models.preisach``), whose staircase kernels, packed
loop state and protocol methods it reuses. ``model`` holds the equations and the readable
reference, ``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="gpreisach", docs="docs/models/preisach.md", default_size=16, max_size=64,
    title="generalised (non-linear) Preisach, input-dependent weight and reversible part (sec. "
          "2.1.2, eq. 2.2)",
    size_help="grid levels L of the two Preisach weights ((L - 1) (L - 2) relay cells)")

__getattr__, __dir__ = family_exports(__name__, globals(), "GPreisachFamily")
