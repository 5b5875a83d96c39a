"""What every identification routine returns."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["FitResult"]


@dataclass(frozen=True, eq=False)
class FitResult:
    """Outcome of a fit.

    Attributes
    ----------
    structure, params
        The fitted model (the family's frozen dataclasses).
    cost : float
        Sum of squared errors (eq. 5.9) on the data as given (normalised by the caller).
    n_evaluations : int
        Model runs over all starts (a Jacobian counts as one).
    seconds : float
        Wall time of the fit.
    converged : bool
        Whether the best start met a convergence tolerance (not merely its evaluation budget).
    message : str
        The solver's message for the best start.
    n_starts : int
    theta : array or None
        The optimum in optimiser coordinates, when the fit used a bounded solver.
    bounds : (lower, upper) or None
        That solver's bounds, so reports can flag parameters sitting on one.
    """

    structure: Any
    params: Any
    cost: float
    n_evaluations: int
    seconds: float
    converged: bool
    message: str
    n_starts: int
    theta: Any = None
    bounds: Any = None
