"""PWL ladder circuit of Parodi, Storace and Cincotti, sec. 2.1.5 of the reference document
(docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import fit, model
from .family import LadderFamily
from .fit import *
from .model import *

FAMILY = LadderFamily()

__all__ = ["FAMILY", "LadderFamily"] + model.__all__ + fit.__all__
