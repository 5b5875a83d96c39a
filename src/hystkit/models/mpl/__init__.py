"""Modified Power-Law (mPL) model, sec. 5.3.1 of the reference document (docs/models/mpl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import model
from .family import MplFamily
from .fit import default_starts, fit_mpl
from .model import *

FAMILY = MplFamily()

__all__ = ["FAMILY", "MplFamily", "default_starts", "fit_mpl"] + model.__all__
