"""Least squares under the reference document's weight-sum constraint (sec. 5.3.3).

The document fitted the mPL with MATLAB's fmincon (interior point) "subjected to a single
constraint b = 10^2 that defines the maximum of the sum of the optimized weights"; paper 9.1
says "the sum of all of the weights is smaller than 10^2". A signed sum bounded above only
stops the weights growing one way, so the constraint is taken on their magnitudes,
``sum_k |w_k| <= B``. That is not smooth where a weight is 0, so the problem is written with
one auxiliary variable per weight::

    minimise  0.5 sum(r(theta)^2)   over (theta, t)
    subject to  t_k - w_k >= 0,  t_k + w_k >= 0,  B - sum_k t_k >= 0,  theta in its box

which has the same minimisers (``t_k = |w_k|`` wherever the sum is active) and only linear
constraints. It goes to scipy's SLSQP with the exact gradient ``J^T r`` of the family's
one-pass normal equations; SLSQP's quasi-Newton model of the Hessian starts from the identity,
so the coordinates are scaled by the Gauss-Newton diagonal ``sqrt(diag J^T J)`` at the start.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..errors import FitDivergedError
from ._clock import FitTimer
from ._normal_equations import NormalEquations
from ._result import FitResult

__all__ = ["ConstrainedSolution", "constrain_fit", "minimise_with_weight_sum"]


@dataclass(frozen=True)
class ConstrainedSolution:
    """The result of :func:`minimise_with_weight_sum`.

    Parameters
    ----------
    theta : numpy.ndarray
        The solution in the caller's coordinates.
    cost : float
        Its sum of squared residuals.
    weight_sum : float
        ``sum |w_k|`` at the solution.
    active : bool
        Whether the constraint holds with equality (to 1e-6 relative).
    n_runs : int
        Normal-equation passes used.
    converged : bool
        Whether SLSQP reported success.
    message : str
        SLSQP's message.
    column_norms : numpy.ndarray
        ``sqrt(diag(J^T J))`` at the solution (the fit's sensitivity).
    """

    theta: np.ndarray
    cost: float
    weight_sum: float
    active: bool
    n_runs: int
    converged: bool
    message: str
    column_norms: np.ndarray


def minimise_with_weight_sum(normal_equations: Callable[[np.ndarray], NormalEquations],
                             theta0: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
                             weights: np.ndarray, weight_sum_max: float, *,
                             max_iter: int = 300) -> ConstrainedSolution:
    """Minimise ``sum(r^2)`` subject to ``sum |theta[weights]| <= weight_sum_max`` and the box.

    Parameters
    ----------
    normal_equations : callable
        ``theta -> NormalEquations`` (``0.5 sum(r^2)``, ``J^T J``, ``J^T r``), finite inside
        the box.
    theta0 : array, shape (p,)
        Start. Clipped into the box; if its weights break the constraint they are scaled
        down onto it, so the solve starts feasible.
    bounds : (lower, upper)
        The box, arrays of shape (p,).
    weights : array of int
        Indices of the constrained coordinates (the weights ``w_0 .. w_N``).
    weight_sum_max : float
        The bound ``B`` (> 0); the document used 100.
    max_iter : int, default 300
        SLSQP iteration limit.

    Returns
    -------
    ConstrainedSolution

    Raises
    ------
    ValueError
        If ``weight_sum_max`` is not positive and finite, or the start has no finite cost.
    """
    from scipy.optimize import minimize  # here: only this option needs it

    if not (np.isfinite(weight_sum_max) and weight_sum_max > 0):
        raise ValueError(f"the weight-sum bound must be positive and finite, got "
                         f"{weight_sum_max!r}")
    lower, upper = (np.asarray(b, dtype=float) for b in bounds)
    weights = np.asarray(weights, dtype=int)
    theta0 = np.clip(np.asarray(theta0, dtype=float), lower, upper)
    total = np.abs(theta0[weights]).sum()
    if total > weight_sum_max:
        theta0[weights] *= weight_sum_max / total * (1 - 1e-9)
    first = normal_equations(theta0)
    if not np.isfinite(first.cost):
        raise ValueError("the constrained fit's start has no finite cost")
    p, m = theta0.size, weights.size
    # scaled coordinates s = theta * d: the quasi-Newton model starts near J^T J
    d = np.sqrt(np.maximum(np.diag(first.jtj), 1e-12 * max(1.0, np.max(np.diag(first.jtj)))))
    cost_scale = max(first.cost, 1e-300)
    cache: dict = {}
    n_runs = [1]

    def evaluate(z: np.ndarray) -> NormalEquations:
        key = z.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = normal_equations(z[:p] / d)
            n_runs[0] += 1
        return cache[key]

    def fun(z: np.ndarray) -> float:
        cost = evaluate(z).cost
        return cost / cost_scale if np.isfinite(cost) else 1e30

    def grad(z: np.ndarray) -> np.ndarray:
        ne = evaluate(z)
        g = np.zeros(p + m)
        if np.isfinite(ne.cost):
            g[:p] = ne.jtr / d / cost_scale
        return g

    # constraints on z = [s, t]: t_k -+ w_k >= 0 (w_k = s_k / d_k), B - sum t >= 0
    a = np.zeros((2 * m + 1, p + m))
    for row, (k, i) in enumerate(zip(range(m), weights, strict=True)):
        a[2 * row, i], a[2 * row, p + k] = -1.0 / d[i], 1.0
        a[2 * row + 1, i], a[2 * row + 1, p + k] = 1.0 / d[i], 1.0
    a[-1, p:] = -1.0
    b = np.zeros(2 * m + 1)
    b[-1] = weight_sum_max
    z0 = np.r_[theta0 * d, np.abs(theta0[weights])]
    box = [*zip(lower * d, upper * d, strict=True), *[(0.0, weight_sum_max)] * m]
    sol = minimize(fun, z0, jac=grad, method="SLSQP", bounds=box,
                   constraints=[{"type": "ineq", "fun": lambda z: a @ z + b,
                                 "jac": lambda z: a}],
                   options={"maxiter": max_iter, "ftol": 1e-14})
    theta = np.clip(sol.x[:p] / d, lower, upper)
    excess = np.abs(theta[weights]).sum() / weight_sum_max
    if excess > 1:  # SLSQP's constraint tolerance: back onto the feasible set
        theta[weights] /= excess
    last = normal_equations(theta)
    n_runs[0] += 1
    weight_sum = float(np.abs(theta[weights]).sum())
    return ConstrainedSolution(theta=theta, cost=2.0 * float(last.cost), weight_sum=weight_sum,
                               active=weight_sum >= weight_sum_max * (1 - 1e-6),
                               n_runs=n_runs[0], converged=bool(sol.success),
                               message=str(sol.message),
                               column_norms=np.sqrt(np.maximum(np.diag(last.jtj), 0.0)))


def constrain_fit(result: FitResult, normal_equations: Callable[[np.ndarray], NormalEquations],
                  weights: np.ndarray, weight_sum_max: float,
                  to_params: Callable[[np.ndarray], Any], *,
                  accept: Callable[[Any], bool] | None = None,
                  accept_reason: str = "rejected by the acceptance test",
                  label: str = "sum |w|") -> FitResult:
    """A family's unconstrained fit carried on to the constrained optimum ``sum |w| <= B``.

    The constrained solve starts from the unconstrained optimum (its weights scaled onto the
    constraint when they break it); where the optimum already satisfies it, the solve stays
    there, since it is a KKT point of the constrained problem.

    Parameters
    ----------
    result : FitResult
        The family's fit (SSE, with ``theta`` and ``bounds`` recorded).
    normal_equations : callable
        The family's one-pass ``theta -> NormalEquations`` of the SSE.
    weights : array of int
        Indices of ``w_0 .. w_N`` in ``theta``.
    weight_sum_max : float
        The bound ``B``.
    to_params : callable
        ``theta -> params``.
    accept : callable, optional
        As the family's fit: the constrained result must pass it.
    accept_reason : str
        Why `accept` vetoes, for the error.
    label : str, default "sum |w|"
        What the bound limits, for the message.

    Returns
    -------
    FitResult
        The constrained optimum: its SSE, ``converged`` as SLSQP reports, a message that
        gives ``sum |w|`` and whether the constraint is active, and ``constraint`` set where
        it is.

    Raises
    ------
    ValueError
        If the fit minimised anything but the unweighted SSE (the constraint is solved on it).
    FitDivergedError
        If `accept` rejects the constrained optimum.
    """
    if result.loss != "linear" or result.weighted:
        raise ValueError(f"the weight-sum constraint is solved on the SSE (eq. 5.9), not on "
                         f"the {result.objective_label}")
    timer = FitTimer()
    sol = minimise_with_weight_sum(normal_equations, result.theta, result.bounds, weights,
                                   weight_sum_max)
    params = to_params(sol.theta)
    if accept is not None and not accept(params):
        raise FitDivergedError(f"the fit failed: the constrained optimum ({label} <= "
                               f"{weight_sum_max:g}) was rejected ({accept_reason})")
    state = "active" if sol.active else "inactive"
    return replace(result, params=params, theta=sol.theta, cost=sol.cost, objective=sol.cost,
                   converged=sol.converged, n_evaluations=result.n_evaluations + sol.n_runs,
                   seconds=result.seconds + timer.seconds(),
                   sensitivity=sol.column_norms,
                   constraint=f"{label} <= {weight_sum_max:g}" if sol.active else None,
                   message=f"SLSQP under {label} <= {weight_sum_max:g} ({state}: {label} = "
                           f"{sol.weight_sum:.6g}): {sol.message}")
