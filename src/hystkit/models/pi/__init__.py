"""Kuhnen's modified Prandtl-Ishlinskii model with creep, sec. 2.1.6 (docs/models/pi.md).

``model`` holds the equations, the analytical inverse (eq. 2.19) and the readable reference,
``kernels`` the compiled loops, ``fit`` the identification (Kuhnen's generalised error, one
bounded linear least-squares solve), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .family import PiFamily
from .fit import MIN_SLOPE, fit_pi, make_structure, output_thresholds
from .model import (
    InverseParts,
    PiParams,
    PiStructure,
    deadzone,
    instantaneous_weights,
    inverse_parts,
    inverse_pi,
    inverse_play_states,
    inverse_superposition,
    invert,
    invert_step,
    not_invertible_reason,
    play,
    rest_input,
    rest_state,
    simulate,
    simulate_reference,
    step,
)

FAMILY = PiFamily()

__all__ = ["FAMILY", "MIN_SLOPE", "InverseParts", "PiFamily", "PiParams", "PiStructure",
           "deadzone", "fit_pi", "instantaneous_weights", "inverse_parts", "inverse_pi",
           "inverse_play_states", "inverse_superposition", "invert", "invert_step",
           "make_structure", "not_invertible_reason", "output_thresholds", "play", "rest_input",
           "rest_state", "simulate", "simulate_reference", "step"]
