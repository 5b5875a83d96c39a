"""Bobbio-Marrucci spring/piston chain, sec. 2.1.4 of the reference document
(docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import fit, model
from .family import BobbioFamily
from .fit import *
from .model import *

FAMILY = BobbioFamily()

__all__ = ["FAMILY", "BobbioFamily"] + model.__all__ + fit.__all__
