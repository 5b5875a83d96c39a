"""Polynomial modified Power-Law (mPL) model, sec. 5.3.5 and paper 9.2 (docs/models/mpl_poly.md).

``model`` holds the equations, limit, rest points, inverse and readable reference, ``kernels``
the compiled loops (with the loop blocks), ``fit`` the identification, ``presets`` paper 9.2's
tables, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .family import MplPolyFamily
from .fit import canonical, default_starts, fit_mpl_poly
from .model import (
    MplPolyParams,
    MplPolyStructure,
    equilibria,
    inverse_branch,
    invert,
    invert_step,
    knee_points,
    output_branch,
    output_current,
    output_slope,
    resistor_current,
    resistor_slope,
    rest_state,
    rest_voltages,
    simulate,
    simulate_reference,
    simulate_with_jacobian,
    step,
)
from .presets import PAPER_9_2_TABLE_I, PAPER_9_2_TABLE_II, paper_9_2_params

FAMILY = MplPolyFamily()

__all__ = ["FAMILY", "PAPER_9_2_TABLE_I", "PAPER_9_2_TABLE_II", "MplPolyFamily",
           "MplPolyParams", "MplPolyStructure", "canonical", "default_starts", "equilibria",
           "fit_mpl_poly", "inverse_branch", "invert", "invert_step", "knee_points",
           "output_branch", "output_current", "output_slope", "paper_9_2_params",
           "resistor_current", "resistor_slope", "rest_state", "rest_voltages", "simulate",
           "simulate_reference", "simulate_with_jacobian", "step"]
