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

import numpy as np

from ._normal_equations import NormalEquations, RunCounter, SolveResult

__all__ = ["solve_trust_region"]

_EPS = np.finfo(float).eps


def _norm(v: np.ndarray) -> float:
    """Euclidean norm of a short vector (np.linalg.norm's dispatch costs more than the sum)."""
    return math.sqrt(float(v @ v))
_MESSAGES = {
    -3: "the cost is not finite at the start",
    0: "budget exhausted: the maximum number of function evaluations was reached",
    1: "gtol termination condition is satisfied",
    2: "ftol termination condition is satisfied",
    3: "xtol termination condition is satisfied",
    4: "both ftol and xtol termination conditions are satisfied",
}


def solve_trust_region(normal_equations: Callable[[np.ndarray], NormalEquations],
                       x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, *,
                       cost: Callable[[np.ndarray], float] | None = None,
                       max_nfev: int = 200, ftol: float = 1e-8, xtol: float = 1e-8,
                       gtol: float = 1e-8) -> SolveResult:
    """Minimise ``0.5 * sum(r(x)**2)`` over ``lower <= x <= upper`` (``x0`` strictly inside).

    Parameters as :func:`~._lm.solve_lm`: ``cost``, when given, judges trial points alone and
    the normal equations are formed only at accepted ones.
    """
    lb, ub = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    x = _strictly_feasible(np.asarray(x0, dtype=float), lb, ub)
    runs = RunCounter()
    ne = runs.trial(normal_equations, x)
    if not np.isfinite(ne.cost):
        return _result(x, np.inf, -3, runs, None)
    scale_inv = _column_norms(ne.jtj)
    scale_inv[scale_inv == 0] = 1.0
    root = _square_root(ne.jtj)
    v, dv = _coleman_li(x, ne.jtr, lb, ub)
    v[dv != 0] *= scale_inv[dv != 0]
    delta = _norm(x * scale_inv / v ** 0.5) or 1.0
    alpha, status = 0.0, None
    while True:
        g = ne.jtr
        v, dv = _coleman_li(x, g, lb, ub)
        g_norm = float(np.max(np.abs(g * v)))
        if g_norm < gtol:
            status = 1
        if status is not None or runs.nfev >= max_nfev:
            break
        v[dv != 0] *= scale_inv[dv != 0]
        d = v ** 0.5 / scale_inv
        diag_h = g * dv / scale_inv
        g_h = d * g
        h_h = ne.jtj * np.outer(d, d)  # J_h^T J_h
        _, sv, vecs_t = np.linalg.svd(np.vstack([root * d, np.diag(diag_h ** 0.5)]),
                                      full_matrices=False)
        eig, vecs = sv ** 2, vecs_t.T
        sg = vecs.T @ g_h  # scipy's s * U^T f
        theta = max(0.995, 1.0 - g_norm)
        actual = -1.0
        while actual <= 0 and runs.nfev < max_nfev:
            p_h, alpha = _trust_region_step(eig, vecs, sg, delta, alpha)
            p = d * p_h
            step, step_h, predicted = _select_step(x, h_h, diag_h, g_h, p, p_h, d, delta,
                                                   lb, ub, theta)
            x_new = _strictly_feasible(x + step, lb, ub)
            if cost is None:
                trial = runs.trial(normal_equations, x_new)
                new_cost = trial.cost
            else:
                trial, new_cost = None, runs.cost(cost, x_new)
            step_h_norm = _norm(step_h)
            if not np.isfinite(new_cost):
                delta = 0.25 * step_h_norm
                continue
            actual = ne.cost - new_cost
            new_delta, ratio = _update_radius(delta, actual, predicted, step_h_norm,
                                              step_h_norm > 0.95 * delta)
            status = _termination(actual, ne.cost, _norm(step), _norm(x),
                                  ratio, ftol, xtol)
            if status is not None:
                break
            alpha *= delta / new_delta
            delta = new_delta
        if actual > 0:
            x = x_new
            ne = trial if trial is not None else runs.normal(normal_equations, x)
            scale_inv = np.maximum(scale_inv, _column_norms(ne.jtj))
            root = _square_root(ne.jtj)
    return _result(x, ne.cost, 0 if status is None else status, runs, _column_norms(ne.jtj))


def _result(x, cost, status, runs, column_norms) -> SolveResult:
    return SolveResult(x=x, cost=float(cost), status=status, message=_MESSAGES[status],
                       nfev=runs.nfev, njev=runs.njev, n_runs=runs.n_runs,
                       column_norms=column_norms)


def _square_root(jtj: np.ndarray) -> np.ndarray:
    """An ``R`` with ``R^T R = J^T J``: the Cholesky factor, else from the eigendecomposition."""
    try:
        return np.linalg.cholesky(jtj).T
    except np.linalg.LinAlgError:
        eig, vecs = np.linalg.eigh(jtj)
        return np.sqrt(np.maximum(eig, 0.0))[:, None] * vecs.T


def _column_norms(jtj: np.ndarray) -> np.ndarray:
    return np.sqrt(np.maximum(np.diag(jtj), 0.0))


def _coleman_li(x, g, lb, ub):
    """Coleman-Li scaling vector ``v`` and its derivative sign ``dv`` (scipy's
    ``CL_scaling_vector``)."""
    v, dv = np.ones_like(x), np.zeros_like(x)
    mask = (g < 0) & np.isfinite(ub)
    v[mask], dv[mask] = ub[mask] - x[mask], -1.0
    mask = (g > 0) & np.isfinite(lb)
    v[mask], dv[mask] = x[mask] - lb[mask], 1.0
    return v, dv


def _strictly_feasible(x, lb, ub):
    """Points on or past a bound moved to the next float inside (scipy, ``rstep=0``)."""
    x = np.array(x, dtype=float)
    low, high = x <= lb, x >= ub
    x[low] = np.nextafter(lb[low], ub[low])
    x[high] = np.nextafter(ub[high], lb[high])
    tight = (x < lb) | (x > ub)
    x[tight] = 0.5 * (lb[tight] + ub[tight])
    return x


def _trust_region_step(eig, vecs, sg, delta, alpha, rtol=0.01, max_iter=10):
    """Moré's solution of ``min ||J_h p + r||, ||p|| <= delta`` from ``M = V diag(eig) V^T``
    (``eig`` descending, the squared singular values) and ``sg = V^T g_h``; returns
    ``(p, alpha)`` (scipy's ``solve_lsq_trust_region``)."""
    full_rank = eig[-1] ** 0.5 > _EPS * 2 * eig.size * eig[0] ** 0.5
    if full_rank:
        p = -vecs @ (sg / eig)
        if _norm(p) <= delta:
            return p, 0.0

    def phi_and_derivative(a):
        denom = eig + a
        p_norm = _norm(sg / denom)
        return p_norm - delta, -np.sum(sg ** 2 / denom ** 3) / p_norm

    alpha_upper = _norm(sg) / delta
    if full_rank:
        phi, phi_prime = phi_and_derivative(0.0)
        alpha_lower = -phi / phi_prime
    else:
        alpha_lower = 0.0
    if not full_rank and alpha == 0:
        alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
    for _ in range(max_iter):
        if alpha < alpha_lower or alpha > alpha_upper:
            alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
        phi, phi_prime = phi_and_derivative(alpha)
        if phi < 0:
            alpha_upper = alpha
        ratio = phi / phi_prime
        alpha_lower = max(alpha_lower, alpha - ratio)
        alpha -= (phi + delta) * ratio / delta
        if abs(phi) < rtol * delta:
            break
    p = -vecs @ (sg / (eig + alpha))
    return p * (delta / _norm(p)), alpha


def _quadratic(h_h, g_h, s, diag_h):
    """``0.5 s^T (J_h^T J_h + diag_h) s + g_h . s``."""
    return 0.5 * (s @ h_h @ s + (s * diag_h) @ s) + g_h @ s


def _quadratic_1d(h_h, g_h, s, diag_h, s0=None):
    """Coefficients of the model along ``s0 + t s``: ``a t^2 + b t (+ c)``."""
    a = 0.5 * (s @ h_h @ s + (s * diag_h) @ s)
    b = g_h @ s
    if s0 is None:
        return a, b, 0.0
    b += s0 @ h_h @ s + (s0 * diag_h) @ s
    c = 0.5 * (s0 @ h_h @ s0 + (s0 * diag_h) @ s0) + g_h @ s0
    return a, b, c


def _minimize_1d(a, b, lo, hi, c=0.0):
    t = [lo, hi]
    if a != 0:
        extremum = -0.5 * b / a
        if lo < extremum < hi:
            t.append(extremum)
    t = np.asarray(t)
    values = t * (a * t + b) + c
    i = int(np.argmin(values))
    return t[i], values[i]


def _step_to_bound(x, s, lb, ub):
    """Largest ``t`` with ``x + t s`` in the box, and which coordinates reach it (signed)."""
    steps = np.full_like(x, np.inf)
    nz = s != 0
    with np.errstate(over="ignore"):
        steps[nz] = np.maximum((lb - x)[nz] / s[nz], (ub - x)[nz] / s[nz])
    t = np.min(steps)
    return t, np.equal(steps, t) * np.sign(s).astype(int)


def _intersect_sphere(x, s, delta):
    """Both ``t`` with ``||x + t s|| = delta``, ascending."""
    a, b, c = s @ s, x @ s, x @ x - delta ** 2
    q = -(b + np.copysign(np.sqrt(b * b - a * c), b))
    t1, t2 = q / a, c / q
    return (t1, t2) if t1 < t2 else (t2, t1)


def _select_step(x, h_h, diag_h, g_h, p, p_h, d, delta, lb, ub, theta):
    """scipy's ``select_step``: the trust-region step if feasible, else the best of its
    strictly feasible part, its reflection off the bound, and the scaled gradient step.
    Returns ``(step, step_h, predicted reduction)``."""
    if np.all((x + p >= lb) & (x + p <= ub)):
        return p, p_h, -_quadratic(h_h, g_h, p_h, diag_h)
    p_stride, hits = _step_to_bound(x, p, lb, ub)
    r_h = p_h.copy()
    r_h[hits.astype(bool)] *= -1
    r = d * r_h
    p, p_h = p * p_stride, p_h * p_stride
    _, to_tr = _intersect_sphere(p_h, r_h, delta)
    to_bound, _ = _step_to_bound(x + p, r, lb, ub)
    r_stride = min(to_bound, to_tr)
    if r_stride > 0:
        r_lo = (1 - theta) * p_stride / r_stride
        r_hi = theta * to_bound if r_stride == to_bound else to_tr
    else:
        r_lo, r_hi = 0.0, -1.0
    if r_lo <= r_hi:
        a, b, c = _quadratic_1d(h_h, g_h, r_h, diag_h, s0=p_h)
        r_stride, r_value = _minimize_1d(a, b, r_lo, r_hi, c=c)
        r_h = r_h * r_stride + p_h
        r = r_h * d
    else:
        r_value = np.inf
    p, p_h = p * theta, p_h * theta
    p_value = _quadratic(h_h, g_h, p_h, diag_h)
    ag_h = -g_h
    ag = d * ag_h
    to_tr = delta / _norm(ag_h)
    to_bound, _ = _step_to_bound(x, ag, lb, ub)
    ag_stride = theta * to_bound if to_bound < to_tr else to_tr
    a, b, _ = _quadratic_1d(h_h, g_h, ag_h, diag_h)
    ag_stride, ag_value = _minimize_1d(a, b, 0.0, ag_stride)
    if p_value < r_value and p_value < ag_value:
        return p, p_h, -p_value
    if r_value < p_value and r_value < ag_value:
        return r, r_h, -r_value
    return ag * ag_stride, ag_h * ag_stride, -ag_value


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
