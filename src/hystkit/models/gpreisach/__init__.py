"""Generalised (non-linear) Preisach model of Mayergoyz and Friedman, sec. 2.1.2, eq. 2.2
(docs/models/preisach.md).

It extends the classical model (``hystkit.models.preisach``), whose staircase kernels, packed
loop state and protocol methods it reuses. ``model`` holds the equations and the readable
reference, ``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import fit, model
from .family import GPreisachFamily
from .fit import *
from .model import *

FAMILY = GPreisachFamily()

__all__ = ["FAMILY", "GPreisachFamily"] + model.__all__ + fit.__all__
