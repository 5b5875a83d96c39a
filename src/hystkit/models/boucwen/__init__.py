"""Bouc-Wen hysteresis with linear dynamics, a single-degree-of-freedom oscillator (beyond the
reference document; docs/models/boucwen.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import fit, model
from .family import BoucWenFamily
from .fit import *
from .model import *

FAMILY = BoucWenFamily()

__all__ = ["FAMILY", "BoucWenFamily"] + model.__all__ + fit.__all__
