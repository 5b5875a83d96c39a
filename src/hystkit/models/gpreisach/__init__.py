"""Generalised (non-linear) Preisach model of Mayergoyz and Friedman, sec. 2.1.2, eq. 2.2
(docs/models/preisach.md).

It extends the classical model (``hystkit.models.preisach``), whose staircase kernels, packed
loop state and protocol methods it reuses. ``model`` holds the equations and the readable
reference, ``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .family import GPreisachFamily

FAMILY = GPreisachFamily()

# The model's equations, its fit and its numba kernels load when one of their names is first
# used, so that the registry (hystkit fit --help) lists the family without compiling anything.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"model": ("*",), "fit": ("*",)},
    first=("FAMILY", "GPreisachFamily"))
