"""Chua-Stromsmoe model, sec. 2.1.3 of the reference document (docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import fit, model
from .family import ChuaFamily
from .fit import *
from .model import *

FAMILY = ChuaFamily()

__all__ = ["FAMILY", "ChuaFamily"] + model.__all__ + fit.__all__
