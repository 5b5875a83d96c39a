"""What every identification routine returns."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ._losses import cost_label

__all__ = ["INSENSITIVE", "BoundHit", "FitResult"]

# A coordinate whose Jacobian column is below this share of the largest column does not affect
# the model output at the optimum (e.g. V_T of an mPL cell at the Euler slope cap: exactly 0).
INSENSITIVE = 1e-10


@dataclass(frozen=True)
class BoundHit:
    """An optimiser coordinate on (or within a tolerance of) one of its bounds.

    Parameters
    ----------
    index : int
        Position in ``theta``.
    name : str
        The coordinate's name if the fit gave names, else ``theta[index]``.
    side : {"lower", "upper"}
        Which bound it is on.
    limit : str or None
        Why this hit is not a failure: for a bound that is the model's own limit (e.g. the
        mPL's Euler slope cap, eq. 5.28-5.29) the family's note on what it means; for a
        coordinate the model output does not depend on at the optimum, a note saying so (its
        bound holds nothing). None for a search box hit.
    """

    index: int
    name: str
    side: str
    limit: str | None = None


@dataclass(frozen=True, eq=False)
class FitResult:
    """Outcome of a fit.

    Parameters
    ----------
    structure, params : object
        The fitted model (the family's frozen dataclasses).
    cost : float
        Sum of squared errors (eq. 5.9) on the data as given (normalised by the caller),
        unweighted whatever cost the fit minimised (R^2 and AIC/BIC use it).
    n_evaluations : int
        Model runs over all starts: with the normal-equation solvers ("tr", "lm") each run
        yields the cost and ``J^T J``, ``J^T r`` (or the cost alone); with "trf" a residual and
        a Jacobian evaluation count one each.
    seconds : float
        Wall time of the fit.
    converged : bool
        Whether the best start met a convergence tolerance (not merely its evaluation budget).
    message : str
        The solver's message for the best start.
    n_starts : int
        Number of starts the fit was given.
    theta : array or None
        The optimum in optimiser coordinates, when the fit used a bounded solver.
    bounds : (lower, upper) or None
        That solver's bounds, so reports can flag parameters sitting on one.
    names : tuple of str or None
        Names of the ``theta`` coordinates (optimiser coordinates, e.g. ``log_G[2]``).
    limits : (lower labels, upper labels) or None
        Per coordinate and side, the note of a bound that is a limit of the model itself
        (reaching it is a property of the fitted model, not a search box hit), else None.
    sensitivity : array or None
        Column norms of the residual's Jacobian at the optimum, ``sqrt(diag(J^T J))`` (how
        much each coordinate moves the model output there).
    objective : float or None
        The cost the fit minimised, ``sum_i f^2 rho(w_i r_i^2 / f^2)`` (``cost`` for the SSE);
        None if the fit did not record it.
    loss : str
        Its loss (``"linear"``: squared residuals; see
        :data:`hystkit.identification.LOSSES`).
    f_scale : float
        Its robust loss's residual scale (unused by "linear").
    weighted : bool
        Whether it weighted the residuals.
    constraint : str or None
        The constraint the optimum lies on (active), e.g. ``"sum |w| <= 100"``: there the
        cost is not stationary, so its Gauss-Newton standard errors do not apply. None if
        the fit was unconstrained or the constraint inactive.
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
    names: Any = None
    limits: Any = None
    sensitivity: Any = None
    objective: float | None = None
    loss: str = "linear"
    f_scale: float = 1.0
    weighted: bool = False
    constraint: str | None = None

    @property
    def objective_label(self) -> str:
        """What ``objective`` is, for reports (:func:`~._losses.cost_label`): ``"SSE"``,
        ``"SSE weighted by per-sample weights"`` or e.g. ``"huber cost (f_scale 0.1)"``."""
        return cost_label(self.loss, self.f_scale,
                          "per-sample weights" if self.weighted else None)

    def bound_hits(self, tolerance: float) -> list[BoundHit] | None:
        """Coordinates of ``theta`` within ``tolerance`` x (bound interval) of a finite bound.

        None when the fit did not record ``theta`` and ``bounds``. A coordinate on a model
        limit carries that limit's note (``BoundHit.limit``), and so does one that does not
        affect the output at the optimum (Jacobian column below ``INSENSITIVE`` x the largest).
        """
        if self.theta is None or self.bounds is None:
            return None
        theta = np.asarray(self.theta, dtype=float)
        lower, upper = (np.asarray(b, dtype=float) for b in self.bounds)
        width = np.where(np.isfinite(upper - lower), upper - lower, 1.0)
        tol = tolerance * np.maximum(width, 1e-12)
        free = np.zeros(theta.size, bool)
        if self.sensitivity is not None:
            norms = np.asarray(self.sensitivity, dtype=float)
            free = norms <= INSENSITIVE * max(float(np.max(norms, initial=0.0)), 1e-300)
        hits = []
        for side, on_side in (("lower", np.isfinite(lower) & (theta - lower <= tol)),
                              ("upper", np.isfinite(upper) & (upper - theta <= tol))):
            labels = None if self.limits is None else self.limits[0 if side == "lower" else 1]
            for i in np.flatnonzero(on_side):
                name = self.names[i] if self.names is not None else f"theta[{i}]"
                limit = None if labels is None else labels[i]
                if limit is None and free[i]:
                    limit = (f"{name} does not affect the model output at the optimum (its "
                             f"{side} bound holds nothing)")
                hits.append(BoundHit(int(i), str(name), side, limit))
        return sorted(hits, key=lambda h: h.index)
