"""Classical Preisach model, sec. 2.1.1 and appendix 9.3-9.5 (docs/models/preisach.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops
(shared with the generalised model, ``models/gpreisach``), ``fit`` the identification (least
squares and FORCs), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import fit, kernels, model
from .family import PreisachFamily, StaircaseFamily
from .fit import *
from .model import *
from .model import INVERT_TOL

FAMILY = PreisachFamily()

__all__ = (["FAMILY", "PreisachFamily", "StaircaseFamily", "INVERT_TOL", "kernels"] + model.__all__
           + fit.__all__)
