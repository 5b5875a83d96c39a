"""PWL ladder circuit of Parodi, Storace and Cincotti, sec. 2.1.5 of the reference document
(docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .family import LadderFamily
from .fit import default_starts, fit_ladder
from .model import (
    LadderParams,
    LadderStructure,
    conductance_limit,
    effective_conductance,
    invert,
    invert_step,
    rest_state,
    simulate,
    simulate_reference,
    states,
    step,
)

FAMILY = LadderFamily()

__all__ = ["FAMILY", "LadderFamily", "LadderParams", "LadderStructure", "conductance_limit",
           "default_starts", "effective_conductance", "fit_ladder", "invert", "invert_step",
           "rest_state", "simulate", "simulate_reference", "states", "step"]
