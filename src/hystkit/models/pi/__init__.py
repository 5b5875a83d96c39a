"""Kuhnen's modified Prandtl-Ishlinskii model with creep, sec. 2.1.6 (docs/models/pi.md).

``model`` holds the equations, the analytical inverse (eq. 2.19) and the readable reference,
``kernels`` the compiled loops, ``fit`` the identification (Kuhnen's generalised error, one
bounded linear least-squares solve), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import fit, model
from .family import PiFamily
from .fit import *
from .model import *

FAMILY = PiFamily()

__all__ = ["FAMILY", "PiFamily"] + model.__all__ + fit.__all__
