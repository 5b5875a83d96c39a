"""Classical Preisach model, sec. 2.1.1 and appendix 9.3-9.5 (docs/models/preisach.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops
(shared with the generalised model, ``models/gpreisach``), ``fit`` the identification (least
squares and FORCs), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from . import kernels
from .family import PreisachFamily, StaircaseFamily
from .fit import (
    ORIENTATIONS,
    check_data,
    everett_from_forcs,
    fit_oriented,
    fit_preisach,
    smoothness_rows,
    solve_regularised,
)
from .model import (
    INVERT_TOL,
    PreisachParams,
    PreisachStructure,
    antisymmetric,
    cell_regressors,
    check_state,
    demagnetised_state,
    everett,
    everett_from_masses,
    grid,
    invert,
    invert_step,
    kernel_parts,
    masses_from_everett,
    pack_state,
    prepare_run,
    simulate,
    simulate_reference,
    staircase_terms,
    step,
    unpack_state,
    update_staircase,
)

FAMILY = PreisachFamily()

__all__ = ["FAMILY", "INVERT_TOL", "ORIENTATIONS", "PreisachFamily", "PreisachParams",
           "PreisachStructure", "StaircaseFamily", "antisymmetric", "cell_regressors",
           "check_data", "check_state", "demagnetised_state", "everett", "everett_from_forcs",
           "everett_from_masses", "fit_oriented", "fit_preisach", "grid", "invert",
           "invert_step", "kernel_parts", "kernels", "masses_from_everett", "pack_state",
           "prepare_run", "simulate", "simulate_reference", "smoothness_rows",
           "solve_regularised", "staircase_terms", "step", "unpack_state", "update_staircase"]
