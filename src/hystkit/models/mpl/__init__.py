"""Modified Power-Law (mPL) model, sec. 5.3.1 of the reference document (docs/models/mpl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .family import MplFamily
from .fit import default_starts, fit_mpl
from .model import (
    MplParams,
    MplStructure,
    invert,
    invert_step,
    knee_voltage,
    resistor_current,
    simulate,
    simulate_reference,
    step,
)

FAMILY = MplFamily()

__all__ = ["FAMILY", "MplFamily", "MplParams", "MplStructure", "default_starts", "fit_mpl",
           "invert", "invert_step", "knee_voltage", "resistor_current", "simulate",
           "simulate_reference", "step"]
