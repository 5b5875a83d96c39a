"""Power-Law (PL) model as published, sec. 2.1.7, eq. 2.16-2.18 and table 5.1 (docs/models/pl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops (with
the loop blocks), ``fit`` the weight fit for a fixed structure, ``search`` the exhaustive
structural search behind ``hystkit pl-search``, ``family`` the protocol adapter (``FAMILY``).
"""

from . import model
from .family import PlFamily
from .fit import default_starts, fit_pl, solve_weights
from .model import *
from .search import DEFAULT_GRID, format_search_table, structural_search

FAMILY = PlFamily()

__all__ = ["FAMILY", "PlFamily", "DEFAULT_GRID", "format_search_table", "structural_search",
           "default_starts", "fit_pl", "solve_weights"] + model.__all__
