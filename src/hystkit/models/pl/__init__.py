"""Power-Law (PL) model as published, sec. 2.1.7, eq. 2.16-2.18 and table 5.1 (docs/models/pl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops (with
the loop blocks), ``fit`` the weight fit for a fixed structure, ``search`` the exhaustive
structural search behind ``hystkit pl-search``, ``family`` the protocol adapter (``FAMILY``).
"""

from .family import PlFamily
from .fit import default_starts, fit_pl, solve_weights
from .model import (
    PlParams,
    PlStructure,
    basis_breakpoints,
    invert,
    invert_step,
    kernel_args,
    output_resistor,
    output_resistor_inverse,
    output_resistor_slope,
    resistor_current,
    resistor_slope,
    rest_state,
    simulate,
    simulate_reference,
    states,
    step,
)
from .search import DEFAULT_GRID, format_search_table, structural_search

FAMILY = PlFamily()

__all__ = ["DEFAULT_GRID", "FAMILY", "PlFamily", "PlParams", "PlStructure", "basis_breakpoints",
           "default_starts", "fit_pl", "format_search_table", "invert", "invert_step",
           "kernel_args", "output_resistor", "output_resistor_inverse", "output_resistor_slope",
           "resistor_current", "resistor_slope", "rest_state", "simulate", "simulate_reference",
           "solve_weights", "states", "step", "structural_search"]
