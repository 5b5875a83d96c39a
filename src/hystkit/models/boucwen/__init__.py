"""Bouc-Wen hysteresis with linear dynamics, a single-degree-of-freedom oscillator (beyond the
reference document; docs/models/boucwen.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .family import BoucWenFamily
from .fit import fit_boucwen, fit_family, parameter_bounds
from .model import (
    BENCHMARK_PARAMS,
    HOLDS,
    STARTS,
    BoucWenParams,
    BoucWenStructure,
    bandlimited_upsample,
    initial_state,
    rest_state,
    simulate,
    simulate_reference,
    simulate_states,
    step,
)

FAMILY = BoucWenFamily()

__all__ = ["BENCHMARK_PARAMS", "FAMILY", "HOLDS", "STARTS", "BoucWenFamily", "BoucWenParams",
           "BoucWenStructure", "bandlimited_upsample", "fit_boucwen", "fit_family",
           "initial_state", "parameter_bounds", "rest_state", "simulate", "simulate_reference",
           "simulate_states", "step"]
