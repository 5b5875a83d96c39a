"""Bobbio-Marrucci spring/piston chain, sec. 2.1.4 of the reference document
(docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .family import BobbioFamily
from .fit import candidate_thresholds, fit_bobbio
from .model import (
    BobbioParams,
    BobbioStructure,
    forces,
    invert,
    invert_step,
    rest_state,
    simulate,
    simulate_reference,
    step,
)

FAMILY = BobbioFamily()

__all__ = ["FAMILY", "BobbioFamily", "BobbioParams", "BobbioStructure", "candidate_thresholds",
           "fit_bobbio", "forces", "invert", "invert_step", "rest_state", "simulate",
           "simulate_reference", "step"]
