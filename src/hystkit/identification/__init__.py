"""Parameter identification machinery shared by every model family (no family lives here).

Each family's own fit is in its folder, ``hystkit.models.<family>``; the registry of families is
:mod:`hystkit.models`.
"""

from ._clock import FitTimer
from ._least_squares import MAX_WEIGHT, check_fit_data, check_weights, fit_multistart
from ._lm import solve_lm
from ._losses import (
    LOSSES,
    check_cost,
    cost_label,
    loss_slope,
    objective,
    require_linear_loss,
    robust_linear_fit,
)
from ._normal_equations import (
                                ChunkedDifferences,
                                NormalEquations,
                                SolveResult,
                                dense_normal_equations,
)
from ._result import BoundHit, FitResult

__all__ = ["LOSSES", "MAX_WEIGHT", "BoundHit", "ChunkedDifferences", "FitResult", "FitTimer",
           "NormalEquations", "SolveResult", "check_cost", "check_fit_data", "check_weights",
           "cost_label", "dense_normal_equations",
           "fit_multistart", "loss_slope", "objective", "require_linear_loss",
           "robust_linear_fit", "solve_lm"]
