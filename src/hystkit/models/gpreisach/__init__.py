"""Generalised (non-linear) Preisach model of Mayergoyz and Friedman, sec. 2.1.2, eq. 2.2
(docs/models/preisach.md).

It extends the classical model (``hystkit.models.preisach``), whose staircase kernels, packed
loop state and protocol methods it reuses. ``model`` holds the equations and the readable
reference, ``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .family import GPreisachFamily
from .fit import fit_gpreisach
from .model import (
    GPreisachParams,
    GPreisachStructure,
    invert,
    invert_step,
    kernel_parts,
    major_slope,
    reversible,
    reversible_basis,
    simulate,
    simulate_reference,
    step,
)

FAMILY = GPreisachFamily()

__all__ = ["FAMILY", "GPreisachFamily", "GPreisachParams", "GPreisachStructure",
           "fit_gpreisach", "invert", "invert_step", "kernel_parts", "major_slope",
           "reversible", "reversible_basis", "simulate", "simulate_reference", "step"]
