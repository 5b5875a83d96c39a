"""The ``p x p`` arithmetic of one trust-region reflective iteration (:mod:`._trust_region`).

* :func:`scaled_problem` (once per accepted point): the Coleman-Li scaling at ``x``, the scaled
  gradient and Gauss-Newton matrix, ``R`` with ``R^T R = J^T J`` and the SVD of
  ``[R diag(d); diag(diag_h)^(1/2)]``;
* :func:`propose` (once per trial point): Moré's trust-region step for a radius and scipy's
  ``select_step`` among it, its reflection and the scaled gradient.

The arithmetic is scipy's (``optimize/_lsq/trf.py`` and ``common.py``) on ``p``-sized arrays.
It is plain NumPy and LAPACK (through scipy), not numba (issue 29): compiled, these steps took
~3 s of the first fit after installing (``propose`` alone 2.2-2.4 s) to save ~10-25 us per
iteration against a model run of ~150 us or more; here ``propose`` costs ~15-60 us. The
scalar loop of Moré's iteration runs on Python floats, and short vectors stay NumPy arrays
(one call per whole-vector operation).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.linalg import lapack

__all__ = ["coleman_li", "propose", "scaled_problem", "square_root", "strictly_feasible"]

_EPS = np.finfo(float).eps


def coleman_li(x: np.ndarray, g: np.ndarray, lb: np.ndarray,
               ub: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coleman-Li scaling vector ``v`` and its derivative sign ``dv`` (scipy's
    ``CL_scaling_vector``)."""
    v, dv = np.ones(x.size), np.zeros(x.size)
    upper = (g < 0) & np.isfinite(ub)
    v[upper], dv[upper] = ub[upper] - x[upper], -1.0
    lower = (g > 0) & np.isfinite(lb)
    v[lower], dv[lower] = x[lower] - lb[lower], 1.0
    return v, dv


def strictly_feasible(x: np.ndarray, lb: np.ndarray, ub: np.ndarray) -> np.ndarray:
    """Points on or past a bound moved to the next float inside (scipy, ``rstep=0``)."""
    if (lb < x).all() and (x < ub).all():  # the common case: one test
        return x.copy()
    x = x.copy()
    low, high = x <= lb, x >= ub
    x[low] = np.nextafter(lb[low], ub[low])
    high &= ~low
    x[high] = np.nextafter(ub[high], lb[high])
    tight = (x < lb) | (x > ub)
    x[tight] = 0.5 * (lb[tight] + ub[tight])
    return x


def _refuse_non_finite() -> None:
    raise np.linalg.LinAlgError("Array must not contain infs or NaNs.")


def square_root(jtj: np.ndarray) -> np.ndarray:
    """An ``R`` with ``R^T R = J^T J``: the Cholesky factor, else from the eigendecomposition
    (see the accuracy note in :mod:`._trust_region`)."""
    # potrf reads the lower triangle of C-ordered jtj (the upper one of its transpose); a NaN
    # or inf fails it (info > 0)
    factor, info = lapack.dpotrf(jtj.T, lower=0, clean=1)
    if info == 0:
        return factor
    if not np.isfinite(jtj).all():
        _refuse_non_finite()
    eig, vecs, info = lapack.dsyevd(jtj, compute_v=1, lower=1)
    if info != 0:
        raise np.linalg.LinAlgError("Eigenvalues did not converge")
    return np.sqrt(np.maximum(eig, 0.0)).reshape(-1, 1) * vecs.T


@functools.lru_cache(maxsize=16)
def _svd_workspace(m: int, n: int) -> int:
    """gesdd's optimal workspace for an ``m x n`` matrix."""
    work, info = lapack.dgesdd_lwork(m, n, compute_uv=1, full_matrices=0)
    if info != 0:
        raise np.linalg.LinAlgError(f"gesdd workspace query failed ({info})")
    return int(work)


def scaled_problem(x, jtj, g, lb, ub, scale_inv):
    """Scaled problem at ``x``: ``(d, diag_h, g_h, h_h, eig, vecs, sg, g_norm)``.

    ``scale_inv`` is first raised in place to the column norms ``sqrt(diag(J^T J))`` at ``x``
    (``x_scale="jac"``: their running maximum over the accepted points). ``d`` the variable
    scaling, ``diag_h`` the Coleman-Li diagonal, ``g_h = d g``, ``h_h = J_h^T J_h``, ``eig``
    (descending) and ``vecs`` the squared singular values and right singular vectors of
    ``[R diag(d); diag(diag_h)^(1/2)]`` (``R^T R = J^T J``), ``sg = vecs^T g_h``, ``g_norm =
    ||v g||_inf`` (the gtol measure).
    """
    root = square_root(jtj)
    np.maximum(scale_inv, np.sqrt(np.maximum(np.diagonal(jtj), 0.0)), out=scale_inv)
    v, dv = coleman_li(x, g, lb, ub)
    g_norm = float(np.max(np.abs(g * v)))
    moving = dv != 0
    v[moving] *= scale_inv[moving]
    d = np.sqrt(v) / scale_inv
    diag_h = g * dv / scale_inv
    g_h = d * g
    h_h = jtj * np.outer(d, d)
    stacked = np.empty((2 * x.size, x.size), order="F")
    stacked[:x.size] = root * d
    stacked[x.size:] = np.diag(np.sqrt(diag_h))
    if not np.isfinite(stacked).all():
        _refuse_non_finite()
    _, sv, vecs_t, info = lapack.dgesdd(stacked, compute_uv=1, full_matrices=0,
                                        lwork=_svd_workspace(*stacked.shape), overwrite_a=1)
    if info != 0:
        raise np.linalg.LinAlgError("SVD did not converge")
    return d, diag_h, g_h, h_h, sv ** 2, vecs_t.T, vecs_t @ g_h, g_norm


def _norm(v: np.ndarray) -> float:
    return math.sqrt(float(v @ v))


def _secular(sg2: np.ndarray, eig: np.ndarray, alpha: float) -> tuple[float, float]:
    """``||sg / (eig + alpha)||`` and ``sum(sg^2 / (eig + alpha)^3)`` (``sg2 = sg^2``)."""
    q = sg2 / (eig + alpha) ** 2
    return math.sqrt(float(q.sum())), float((q / (eig + alpha)).sum())


def _trust_region_step(eig, vecs, sg, delta, alpha):
    """Moré's solution of ``min ||J_h p + r||, ||p|| <= delta`` from ``M = V diag(eig) V^T``
    and ``sg = V^T g_h``; returns ``(p, alpha)`` (scipy's ``solve_lsq_trust_region``,
    ``rtol = 0.01``, ``max_iter = 10``)."""
    full_rank = eig[-1] ** 0.5 > _EPS * 2 * eig.size * eig[0] ** 0.5
    if full_rank:
        p = -(vecs @ (sg / eig))
        if _norm(p) <= delta:
            return p, 0.0
    sg2 = sg * sg
    alpha_upper = math.sqrt(float(sg2.sum())) / delta
    alpha_lower = 0.0
    if full_rank:
        p_norm, cubes = _secular(sg2, eig, 0.0)
        alpha_lower = (p_norm - delta) * p_norm / cubes
    if not full_rank and alpha == 0:
        alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
    for _ in range(10):
        if alpha < alpha_lower or alpha > alpha_upper:
            alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
        p_norm, cubes = _secular(sg2, eig, alpha)
        phi = p_norm - delta
        if phi < 0:
            alpha_upper = alpha
        ratio = phi / (-cubes / p_norm)
        alpha_lower = max(alpha_lower, alpha - ratio)
        alpha -= (phi + delta) * ratio / delta
        if abs(phi) < 0.01 * delta:
            break
    p = -(vecs @ (sg / (eig + alpha)))
    return p * (delta / _norm(p)), alpha


def _quadratic(h_h, g_h, s, diag_h, s0=None):
    """The model ``0.5 t^T (h_h + diag_h) t + g_h . t`` along ``s0 + t s`` as ``(a, b, c)``
    of ``a t^2 + b t + c`` (scipy's ``build_quadratic_1d``; ``s0`` None: ``b`` and ``c`` 0
    there)."""
    hs = h_h @ s
    a = 0.5 * (float(s @ hs) + float((s * diag_h) @ s))
    if s0 is None:
        return a, float(g_h @ s), 0.0
    b = float(g_h @ s) + float(s0 @ hs) + float((s0 * diag_h) @ s)
    c = 0.5 * (float(s0 @ (h_h @ s0)) + float((s0 * diag_h) @ s0)) + float(g_h @ s0)
    return a, b, c


def _model_value(h_h, g_h, s, diag_h) -> float:
    return 0.5 * (float(s @ (h_h @ s)) + float((s * diag_h) @ s)) + float(g_h @ s)


def _minimize_1d(a, b, lo, hi, c):
    """Minimum of ``a t^2 + b t + c`` on ``[lo, hi]``: ``(t, value)``, ends first on ties."""
    best_t, best = lo, lo * (a * lo + b) + c
    value = hi * (a * hi + b) + c
    if value < best:
        best_t, best = hi, value
    if a != 0:
        t = -0.5 * b / a
        if lo < t < hi:
            value = t * (a * t + b) + c
            if value < best:
                best_t, best = t, value
    return best_t, best


def _step_to_bound(x, s, lb, ub):
    """Largest ``t`` with ``x + t s`` in the box, and which coordinates reach it (signed)."""
    moving = s != 0
    with np.errstate(divide="ignore", invalid="ignore"):
        steps = np.maximum((lb - x) / s, (ub - x) / s)
    steps[~moving] = np.inf
    t = float(steps.min())
    hits = np.where(moving & (steps == t), np.sign(s), 0.0)
    return t, hits


def _intersect_sphere(x, s, delta):
    """Both ``t`` with ``||x + t s|| = delta``, ascending."""
    a, b, c = float(s @ s), float(x @ s), float(x @ x) - delta ** 2
    q = -(b + math.copysign(math.sqrt(b * b - a * c), b))
    t1, t2 = q / a, c / q
    return (t1, t2) if t1 < t2 else (t2, t1)


def propose(x, h_h, diag_h, g_h, eig, vecs, sg, d, delta, alpha, lb, ub, theta):
    """One trial step: ``(x_new, step_norm, step_h_norm, predicted, alpha)``.

    The trust-region step if it stays in the box, else the best of its strictly feasible
    part, its reflection off the first bound hit, and the scaled gradient (scipy's
    ``select_step``); ``x_new`` is made strictly feasible as in scipy.
    """
    p_h, alpha = _trust_region_step(eig, vecs, sg, delta, alpha)
    p = d * p_h
    x_p = x + p
    if (lb <= x_p).all() and (x_p <= ub).all():
        step, step_h, predicted = p, p_h, -_model_value(h_h, g_h, p_h, diag_h)
    else:
        step, step_h, predicted = _select_step(x, h_h, diag_h, g_h, p, p_h, d, delta, lb, ub,
                                               theta)
    return (strictly_feasible(x + step, lb, ub), _norm(step), _norm(step_h), predicted, alpha)


def _select_step(x, h_h, diag_h, g_h, p, p_h, d, delta, lb, ub, theta):
    """scipy's ``select_step`` for a trust-region step ``p`` that leaves the box:
    ``(step, step_h, predicted)``."""
    p_stride, hits = _step_to_bound(x, p, lb, ub)
    r_h = np.where(hits != 0, -p_h, p_h)
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
        a, b, c = _quadratic(h_h, g_h, r_h, diag_h, p_h)
        r_stride, r_value = _minimize_1d(a, b, r_lo, r_hi, c)
        r_h = r_h * r_stride + p_h
        r = r_h * d
    else:
        r_value = math.inf
    p, p_h = p * theta, p_h * theta
    p_value = _model_value(h_h, g_h, p_h, diag_h)
    ag_h = -g_h
    ag = d * ag_h
    to_tr = delta / _norm(ag_h)
    to_bound, _ = _step_to_bound(x, ag, lb, ub)
    ag_stride = theta * to_bound if to_bound < to_tr else to_tr
    a, b, _ = _quadratic(h_h, g_h, ag_h, diag_h)
    ag_stride, ag_value = _minimize_1d(a, b, 0.0, ag_stride, 0.0)
    if p_value < r_value and p_value < ag_value:
        return p, p_h, -p_value
    if r_value < p_value and r_value < ag_value:
        return r, r_h, -r_value
    return ag * ag_stride, ag_h * ag_stride, -ag_value
