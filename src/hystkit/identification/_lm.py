"""Bounded Levenberg-Marquardt on the normal equations ``(cost, J^T J, J^T r)``.

Everything here is of size ``n_params`` or ``n_params^2``: the model run that produced the
normal equations (a compiled one-pass kernel, or chunked finite differences) never hands over
the ``(n_samples x n_params)`` Jacobian, so an iteration costs what the model costs.

Selectable with ``fit_multistart(solver="lm")``; the default is the trust-region port
(:mod:`._trust_region`). On the virtual sensor's mPL fits LM needed about half the model runs
of trf where both converged (3 cells, 8000 samples: 169 against ~360), but in long, curved
valleys it stopped elsewhere (4 cells, 8000 samples, budget exhausted for both: SSE 0.598
against trf's 0.355), so it does not keep the fits' costs as they were.

Method
------
* Step: ``(J^T J + lam D) h = -J^T r`` on the free coordinates, solved (checked positive
  definite by Cholesky) in the variables scaled by ``D^(1/2)``, with Marquardt's scaling
  ``D = diag(J^T J)`` kept as the
  running maximum (Marquardt 1963; Moré 1978, "The Levenberg-Marquardt algorithm:
  implementation and theory", sec. 3) -- the counterpart of scipy's ``x_scale="jac"``.
* Damping: Nielsen's update of ``lam`` from the gain ratio ``rho`` of actual to predicted
  reduction (Madsen, Nielsen & Tingleff 2004, "Methods for non-linear least squares
  problems", alg. 3.16): ``lam *= max(1/3, 1 - (2 rho - 1)^3)`` on success, ``lam *= nu,
  nu *= 2`` on failure.
* Bounds: projected LM with an active set (Bertsekas 1982, "Projected Newton methods for
  optimization problems with simple constraints", SIAM J. Control Optim. 20(2); Kanzow,
  Yamashita & Fukushima 2004, J. Comput. Appl. Math. 172). A coordinate on a bound whose
  gradient points out of the box is held; the step on the others is projected onto the box
  and judged by the gain ratio of the projected step. Because ``D`` is diagonal, a heavily
  damped projected step is a projected scaled-gradient step, which decreases the cost
  unless the point is stationary, so the iteration cannot cycle.

Stopping rules (scipy's defaults and meaning, ``ftol = xtol = gtol = 1e-8``)
----------------------------------------------------------------------------
* ``gtol``: ``max_i |g_i| / (||J_i|| ||r||) < gtol`` over the free coordinates, the cosine
  between the residual and each Jacobian column (MINPACK's test, as scipy's ``method="lm"``).
* ``ftol``: an accepted step with ``dF < ftol F`` and ``rho > 0.25``.
* ``xtol``: ``||h|| < xtol (xtol + ||x||)``, on accepted and rejected steps (as scipy's trf).
* ``max_nfev``: cost evaluations as scipy counts them (status 0, "budget exhausted": not
  converged).
* Stalled (status -2, not converged): the damping grew past ``1e16`` without any step that
  lowers the cost and without meeting ``xtol``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ._normal_equations import STATUS_MESSAGES, NormalEquations, RunCounter, SolveResult

__all__ = ["solve_lm"]

# Initial damping relative to the scaled J^T J (Madsen et al. 2004, eq. 3.14, suggest 1e-6 for
# a good start and 1e-3 otherwise). 0.1 starts between a Gauss-Newton and a gradient step: with
# 1e-3 the first steps from the mPL fit's starts jumped into other basins (a 3-cell noise-free
# fit ended at SSE 4e-3 instead of 1e-24), and 0.1 and 1 both needed half the evaluations.
_TAU = 0.1
_LAM_MAX = 1e16


def solve_lm(normal_equations: Callable[[np.ndarray], NormalEquations],
             x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, *,
             cost: Callable[[np.ndarray], float] | None = None,
             max_nfev: int = 200, ftol: float = 1e-8, xtol: float = 1e-8,
             gtol: float = 1e-8) -> SolveResult:
    """Minimise ``0.5 * sum(r(x)**2)`` over ``lower <= x <= upper``.

    Parameters
    ----------
    normal_equations : callable
        ``x -> NormalEquations`` at ``x``; a non-finite ``cost`` marks ``x`` as rejected.
    x0 : array, shape (p,)
        Start (projected onto the box).
    lower, upper : arrays, shape (p,)
        Finite or infinite bounds, ``lower < upper``.
    cost : callable, optional
        ``x -> 0.5 * sum(r**2)`` alone. When given, trial points are judged by it and the normal
        equations are formed only at accepted points (pays when they cost several model runs,
        as with finite differences); otherwise every trial point gets its normal equations (pays
        when a one-pass kernel yields them at little more than a model run's cost).
    max_nfev : int
        Budget of cost evaluations (trial points and the start; normal equations formed at an
        accepted point after ``cost`` judged it are not counted, as scipy does not count
        Jacobians).
    ftol, xtol, gtol : float
        Tolerances (see the module docstring).

    Returns
    -------
    SolveResult
        The final point, its cost, the stopping ``status`` (> 0: converged) and the
        evaluation counts.
    """
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    x = np.clip(np.asarray(x0, dtype=float), lower, upper)
    hold_band = 1e-10 * np.where(np.isfinite(upper - lower), upper - lower, 1.0)
    state = RunCounter()
    ne = state.trial(normal_equations, x)
    if not np.isfinite(ne.cost):
        return _result(x, np.inf, -3, state, None)
    scale = _initial_scale(ne.jtj)
    lam, nu = _TAU, 2.0
    status = None
    while status is None:
        g = ne.jtr
        held = ((x - lower <= hold_band) & (g > 0)) | ((upper - x <= hold_band) & (g < 0))
        free = ~held
        if _gradient_cosine(ne, free) < gtol:
            status = 1
            break
        if state.nfev >= max_nfev:
            status = 0
            break
        while True:  # inner loop: until a step lowers the cost, or a stopping rule holds
            h = _projected_step(ne, scale, lam, free, x, lower, upper)
            if h is None:  # J^T J not finite or indefinite by rounding: damp harder
                h = np.zeros_like(x)
                predicted, small_step = 0.0, False
            else:
                predicted = -(h @ g) - 0.5 * (h @ ne.jtj @ h)
                small_step = np.linalg.norm(h) < xtol * (xtol + np.linalg.norm(x))
            if not predicted > 0:  # the projection cut the step to an uphill one
                actual, trial = -np.inf, None
            else:
                x_new = x + h
                if cost is None:
                    trial = state.trial(normal_equations, x_new)
                    new_cost = trial.cost
                else:
                    trial, new_cost = None, state.cost(cost, x_new)
                actual = ne.cost - new_cost if np.isfinite(new_cost) else -np.inf
            rho = actual / predicted if predicted > 0 else -np.inf
            if actual > 0:
                lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                nu = 2.0
                small_cost = actual < ftol * ne.cost and rho > 0.25
                status = 4 if small_cost and small_step else 2 if small_cost else (
                    3 if small_step else None)
                x = np.clip(x_new, lower, upper)
                ne = trial if trial is not None else state.normal(normal_equations, x)
                scale = np.maximum(scale, np.diag(ne.jtj))
                break
            lam *= nu
            nu *= 2.0
            if small_step:
                status = 3
            elif lam > _LAM_MAX:
                status = -2
            elif state.nfev >= max_nfev:
                status = 0
            if status is not None:
                break
    return _result(x, ne.cost, status, state, np.sqrt(np.maximum(np.diag(ne.jtj), 0.0)))


def _result(x, cost, status, state, column_norms) -> SolveResult:
    return SolveResult(x=x, cost=float(cost), status=status, message=STATUS_MESSAGES[status],
                       nfev=state.nfev, njev=state.njev, n_runs=state.n_runs,
                       column_norms=column_norms)


def _initial_scale(jtj: np.ndarray) -> np.ndarray:
    """Marquardt's ``D = diag(J^T J)``; a column of zeros keeps a tiny positive entry."""
    diag = np.maximum(np.diag(jtj), 0.0)
    floor = 1e-30 * max(float(np.max(diag, initial=0.0)), 1e-300)
    return np.maximum(diag, floor)


def _gradient_cosine(ne: NormalEquations, free: np.ndarray) -> float:
    """MINPACK's gtol measure: largest ``|J_i^T r| / (||J_i|| ||r||)`` over free columns."""
    norms = np.sqrt(np.maximum(np.diag(ne.jtj), 0.0)) * np.sqrt(2.0 * ne.cost)
    mask = free & (norms > 0)
    if not np.any(mask):
        return 0.0
    return float(np.max(np.abs(ne.jtr[mask]) / norms[mask]))


def _projected_step(ne: NormalEquations, scale: np.ndarray, lam: float, free: np.ndarray,
                    x: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray | None:
    """The damped step on the free coordinates, projected onto the box (``x + h`` inside);
    None when the damped matrix has no Cholesky factor."""
    s = 1.0 / np.sqrt(scale[free])
    a = ne.jtj[np.ix_(free, free)] * np.outer(s, s)
    a[np.diag_indices_from(a)] += lam
    if not np.all(np.isfinite(a)):
        return None
    try:
        np.linalg.cholesky(a)  # positive definite, else the step is not a descent step
    except np.linalg.LinAlgError:
        return None
    h = np.zeros_like(x)
    h[free] = s * np.linalg.solve(a, -ne.jtr[free] * s)
    return np.clip(x + h, lower, upper) - x
