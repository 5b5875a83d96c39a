"""Chua-Stromsmoe model, sec. 2.1.3 of the reference document (docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .family import ChuaFamily
from .fit import default_starts, fit_chua
from .model import (
    ChuaParams,
    ChuaStructure,
    dissipation,
    dissipation_slope,
    invert,
    invert_step,
    kernel_args,
    limits,
    rest_state,
    restoring,
    restoring_inverse,
    simulate,
    simulate_reference,
    step,
)

FAMILY = ChuaFamily()

__all__ = ["FAMILY", "ChuaFamily", "ChuaParams", "ChuaStructure", "default_starts",
           "dissipation", "dissipation_slope", "fit_chua", "invert", "invert_step",
           "kernel_args", "limits", "rest_state", "restoring", "restoring_inverse", "simulate",
           "simulate_reference", "step"]
