"""Polynomial modified Power-Law (mPL) model, sec. 5.3.5 and paper 9.2 (docs/models/mpl_poly.md).

``model`` holds the equations, limit, rest points, inverse and readable reference, ``kernels``
the compiled loops (with the loop blocks), ``fit`` the identification, ``presets`` paper 9.2's
tables, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import model
from .family import MplPolyFamily
from .fit import canonical, default_starts, fit_mpl_poly
from .model import *
from .presets import PAPER_9_2_TABLE_I, PAPER_9_2_TABLE_II, paper_9_2_params

FAMILY = MplPolyFamily()

__all__ = ["FAMILY", "MplPolyFamily", "PAPER_9_2_TABLE_I", "PAPER_9_2_TABLE_II",
           "paper_9_2_params", "canonical", "default_starts", "fit_mpl_poly"] + model.__all__
