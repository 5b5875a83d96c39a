"""Trust-region reflective on the normal equations ``(cost, J^T J, J^T r)``.

scipy's ``least_squares(method="trf", x_scale="jac")`` (Branch, Coleman & Li 1999, "A subspace,
interior, and conjugate gradient method for large-scale bound-constrained minimization
problems", SIAM J. Sci. Comput. 21(1); scipy's ``optimize/_lsq/trf.py``) with every
``(n_samples x n_params)`` operation replaced by its ``n_params``-sized equivalent:

* The trust-region subproblem ``min ||J_h p + r||, ||p|| <= Delta`` (Moré 1977, "The
  Levenberg-Marquardt algorithm: implementation and theory") is solved, as in scipy, on the
  SVD of ``[J_h; diag_h^(1/2)]``, with ``J_h = J diag(d)`` replaced by ``R diag(d)``, ``R`` the
  Cholesky factor of ``J^T J`` (``R^T R = J^T J``, so both have the same singular values and
  right singular vectors). The step ``p(alpha) = -V (V^T g_h / (s^2 + alpha))`` then needs
  only ``g_h = d * J^T r`` (scipy's ``s * U^T f``).
* Quadratic model values ``0.5 ||J_h p||^2 + g_h . p`` come from ``p^T (J_h^T J_h) p``.
* Bounds: Coleman-Li scaling ``v`` (distance to the bound the gradient points at), steps kept
  strictly feasible (``theta`` step-back), and the choice among the trust-region step, its
  reflection off the first bound hit, and the scaled gradient -- all as scipy.
* ``x_scale="jac"``: the running maximum of the column norms ``sqrt(diag(J^T J))``.

The ``p x p`` arithmetic of an iteration is in :mod:`._trust_region_steps`; here
remain the model runs, the radius update and the stopping rules.

Stopping rules are scipy's (``ftol = xtol = gtol = 1e-8``): ``gtol`` on ``||v g||_inf``;
``ftol``: ``dF < ftol F`` with ratio > 0.25; ``xtol``: ``||step|| < xtol (xtol + ||x||)``; status
0 when ``max_nfev`` model runs are spent (budget exhausted, not converged).

Accuracy: the eigenvalues of ``J^T J`` would resolve ``J``'s singular values only down to
``sqrt(eps)`` of the largest, and a fit whose columns differ by 1e10 in norm (a parameter that
stops acting on the output, e.g. ``V_T`` of an mPL cell at the Euler cap) needs more. Each entry
of ``J^T J`` is accurate relative to the product of its two column norms, and Cholesky's error
is bounded by the condition number of the column-scaled matrix (Demmel 1989, "On floating point
errors in Cholesky", LAPACK Working Note 14), so ``R`` carries ``J``'s small singular values
whenever the *correlation* of the columns is well conditioned, however different their norms.
When ``J^T J`` has no Cholesky factor (an exactly zero column, or rank lost to rounding), ``R``
comes from its eigendecomposition. The Gauss-Newton test is scipy's with ``m`` = ``2 p`` rows.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ._normal_equations import STATUS_MESSAGES, NormalEquations, RunCounter, SolveResult
from ._trust_region_steps import coleman_li, propose, scaled_problem, strictly_feasible

__all__ = ["TrustRegionState", "solve_trust_region"]


def _norm(v: np.ndarray) -> float:
    """Euclidean norm of a short vector (np.linalg.norm's dispatch costs more than the sum)."""
    return math.sqrt(float(v @ v))


def solve_trust_region(normal_equations: Callable[[np.ndarray], NormalEquations],
                       x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, *,
                       cost: Callable[[np.ndarray], float] | None = None,
                       max_nfev: int = 200, ftol: float = 1e-8, xtol: float = 1e-8,
                       gtol: float = 1e-8, resume: TrustRegionState | None = None,
                       ) -> SolveResult:
    """Minimise ``0.5 * sum(r(x)**2)`` over ``lower <= x <= upper`` (``x0`` strictly inside).

    Parameters as :func:`~._lm.solve_lm`: ``cost``, when given, judges trial points alone and
    the normal equations are formed only at accepted ones. ``resume``: the ``state`` of an
    earlier result on the same problem, to continue it with ``max_nfev`` more evaluations
    (``x0`` is then ignored): its point is not run again, and scaling and radius go on as if
    it had not stopped.
    """
    lb, ub = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    runs = RunCounter()
    if resume is not None:
        x, ne, delta, alpha = resume.x, resume.ne, resume.delta, resume.alpha
        scale_inv = resume.scale_inv.copy()
    else:
        x = strictly_feasible(np.asarray(x0, dtype=float), lb, ub)
        ne = runs.trial(normal_equations, x)
        if not np.isfinite(ne.cost):
            return _result(x, np.inf, -3, runs, None)
        scale_inv = _column_norms(ne.jtj)
        scale_inv[scale_inv == 0] = 1.0
        v, dv = coleman_li(x, ne.jtr, lb, ub)
        v[dv != 0] *= scale_inv[dv != 0]
        delta = _norm(x * scale_inv / v ** 0.5) or 1.0
        alpha = 0.0
    status = None
    while True:
        # raises scale_inv to the column norms at x (once per accepted point, as scipy)
        d, diag_h, g_h, h_h, eig, vecs, sg, g_norm = scaled_problem(x, ne.jtj, ne.jtr, lb, ub,
                                                                    scale_inv)
        if g_norm < gtol:
            status = 1
        if status is not None or runs.nfev >= max_nfev:
            break
        theta = max(0.995, 1.0 - g_norm)
        x_norm = _norm(x)
        actual = -1.0
        while actual <= 0 and runs.nfev < max_nfev:
            x_new, step_norm, step_h_norm, predicted, alpha = propose(
                x, h_h, diag_h, g_h, eig, vecs, sg, d, delta, alpha, lb, ub, theta)
            if cost is None:
                trial = runs.trial(normal_equations, x_new)
                new_cost = trial.cost
            else:
                trial, new_cost = None, runs.cost(cost, x_new)
            if not np.isfinite(new_cost):
                delta = 0.25 * step_h_norm
                continue
            actual = ne.cost - new_cost
            new_delta, ratio = _update_radius(delta, actual, predicted, step_h_norm,
                                              step_h_norm > 0.95 * delta)
            status = _termination(actual, ne.cost, step_norm, x_norm, ratio, ftol, xtol)
            if status is not None:
                break
            alpha *= delta / new_delta
            delta = new_delta
        if actual > 0:
            x = x_new
            ne = trial if trial is not None else runs.normal(normal_equations, x)
    return _result(x, ne.cost, 0 if status is None else status, runs, _column_norms(ne.jtj),
                   TrustRegionState(x, ne, scale_inv, delta, alpha))


@dataclass(frozen=True)
class TrustRegionState:
    """Where :func:`solve_trust_region` stopped: the last accepted point and its normal
    equations, the running column norms, the radius and Moré's last ``alpha``."""

    x: np.ndarray
    ne: NormalEquations
    scale_inv: np.ndarray
    delta: float
    alpha: float


def _result(x, cost, status, runs, column_norms, state=None) -> SolveResult:
    return SolveResult(x=x, cost=float(cost), status=status, message=STATUS_MESSAGES[status],
                       nfev=runs.nfev, njev=runs.njev, n_runs=runs.n_runs,
                       column_norms=column_norms, state=state)


def _column_norms(jtj: np.ndarray) -> np.ndarray:
    return np.sqrt(np.maximum(np.diag(jtj), 0.0))


def _update_radius(delta, actual, predicted, step_norm, bound_hit):
    if predicted > 0:
        ratio = actual / predicted
    elif predicted == actual == 0:
        ratio = 1.0
    else:
        ratio = 0.0
    if ratio < 0.25:
        delta = 0.25 * step_norm
    elif ratio > 0.75 and bound_hit:
        delta *= 2.0
    return delta, ratio


def _termination(d_cost, cost, dx_norm, x_norm, ratio, ftol, xtol):
    small_cost = d_cost < ftol * cost and ratio > 0.25
    small_step = dx_norm < xtol * (xtol + x_norm)
    if small_cost and small_step:
        return 4
    if small_cost:
        return 2
    return 3 if small_step else None
