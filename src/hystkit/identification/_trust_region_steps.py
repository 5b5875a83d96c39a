"""Compiled ``p x p`` arithmetic of one trust-region reflective iteration (:mod:`._trust_region`).

Each iteration of scipy's ``trf`` does a few dozen small-array operations; as NumPy calls on
``p ~ 10`` they cost ~0.2 ms of interpreter time, as much as a model run on thousands of
samples. Here they are two compiled calls:

* :func:`prepare`: the Coleman-Li scaling at ``x``, the scaled gradient and Gauss-Newton
  matrix, ``R`` with ``R^T R = J^T J`` and the SVD of ``[R diag(d); diag(diag_h)^(1/2)]``
  (once per accepted point);
* :func:`propose`: Moré's trust-region step for a radius and scipy's ``select_step`` among
  it, its reflection and the scaled gradient (once per trial point).

The arithmetic is scipy's (``optimize/_lsq/trf.py`` and ``common.py``), written as loops.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["coleman_li", "prepare", "propose", "square_root", "strictly_feasible"]

_EPS = np.finfo(float).eps
_JIT = {"cache": True, "error_model": "numpy"}


@njit(**_JIT)
def _norm(v):
    return math.sqrt(np.dot(v, v))


@njit(**_JIT)
def coleman_li(x, g, lb, ub):
    """Coleman-Li scaling vector ``v`` and its derivative sign ``dv`` (scipy's
    ``CL_scaling_vector``)."""
    v, dv = np.ones_like(x), np.zeros_like(x)
    for i in range(x.size):
        if g[i] < 0 and np.isfinite(ub[i]):
            v[i], dv[i] = ub[i] - x[i], -1.0
        if g[i] > 0 and np.isfinite(lb[i]):
            v[i], dv[i] = x[i] - lb[i], 1.0
    return v, dv


@njit(**_JIT)
def strictly_feasible(x, lb, ub):
    """Points on or past a bound moved to the next float inside (scipy, ``rstep=0``)."""
    x = x.copy()
    for i in range(x.size):
        if x[i] <= lb[i]:
            x[i] = np.nextafter(lb[i], ub[i])
        elif x[i] >= ub[i]:
            x[i] = np.nextafter(ub[i], lb[i])
        if x[i] < lb[i] or x[i] > ub[i]:
            x[i] = 0.5 * (lb[i] + ub[i])
    return x


@njit(**_JIT)
def square_root(jtj):
    """An ``R`` with ``R^T R = J^T J``: the Cholesky factor, else from the eigendecomposition
    (see the accuracy note in :mod:`._trust_region`)."""
    try:
        return np.linalg.cholesky(jtj).T.copy()
    except Exception:  # noqa: BLE001 -- numba catches no specific class; LinAlgError here
        eig, vecs = np.linalg.eigh(jtj)
        return np.sqrt(np.maximum(eig, 0.0)).reshape(-1, 1) * vecs.T


@njit(**_JIT)
def prepare(x, jtj, g, lb, ub, scale_inv):
    """Scaled problem at ``x``: ``(d, diag_h, g_h, h_h, eig, vecs, sg, g_norm)``.

    ``scale_inv`` is first raised in place to the column norms ``sqrt(diag(J^T J))`` at ``x``
    (``x_scale="jac"``: their running maximum over the accepted points). ``d`` the variable
    scaling, ``diag_h`` the Coleman-Li diagonal, ``g_h = d g``, ``h_h = J_h^T J_h``, ``eig``
    (descending) and ``vecs`` the squared singular values and right singular vectors of
    ``[R diag(d); diag(diag_h)^(1/2)]`` (``R^T R = J^T J``), ``sg = vecs^T g_h``, ``g_norm =
    ||v g||_inf`` (the gtol measure).
    """
    p = x.size
    for i in range(p):
        scale_inv[i] = max(scale_inv[i], math.sqrt(max(jtj[i, i], 0.0)))
    root = square_root(jtj)
    v, dv = coleman_li(x, g, lb, ub)
    g_norm = np.max(np.abs(g * v))
    for i in range(p):
        if dv[i] != 0:
            v[i] *= scale_inv[i]
    d = np.sqrt(v) / scale_inv
    diag_h = g * dv / scale_inv
    g_h = d * g
    h_h = jtj * np.outer(d, d)
    stacked = np.zeros((2 * p, p))
    for i in range(p):
        for j in range(p):
            stacked[i, j] = root[i, j] * d[j]
        stacked[p + i, i] = math.sqrt(diag_h[i])
    _, sv, vecs_t = np.linalg.svd(stacked, full_matrices=False)
    vecs = np.ascontiguousarray(vecs_t.T)
    return d, diag_h, g_h, h_h, sv ** 2, vecs, vecs_t @ g_h, g_norm


@njit(**_JIT)
def _trust_region_step(eig, vecs, sg, delta, alpha):
    """Moré's solution of ``min ||J_h p + r||, ||p|| <= delta`` from ``M = V diag(eig) V^T``
    and ``sg = V^T g_h``; returns ``(p, alpha)`` (scipy's ``solve_lsq_trust_region``,
    ``rtol = 0.01``, ``max_iter = 10``)."""
    full_rank = eig[-1] ** 0.5 > _EPS * 2 * eig.size * eig[0] ** 0.5
    if full_rank:
        p = -(vecs @ (sg / eig))
        if _norm(p) <= delta:
            return p, 0.0
    alpha_upper = _norm(sg) / delta
    alpha_lower = 0.0
    if full_rank:
        p_norm = _norm(sg / eig)
        phi = p_norm - delta
        phi_prime = -np.sum(sg ** 2 / eig ** 3) / p_norm
        alpha_lower = -phi / phi_prime
    if not full_rank and alpha == 0:
        alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
    for _ in range(10):
        if alpha < alpha_lower or alpha > alpha_upper:
            alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
        denom = eig + alpha
        p_norm = _norm(sg / denom)
        phi = p_norm - delta
        phi_prime = -np.sum(sg ** 2 / denom ** 3) / p_norm
        if phi < 0:
            alpha_upper = alpha
        ratio = phi / phi_prime
        alpha_lower = max(alpha_lower, alpha - ratio)
        alpha -= (phi + delta) * ratio / delta
        if abs(phi) < 0.01 * delta:
            break
    p = -(vecs @ (sg / (eig + alpha)))
    return p * (delta / _norm(p)), alpha


@njit(**_JIT)
def _quadratic_1d(h_h, g_h, s, diag_h, s0):
    """Coefficients of the model ``0.5 t^T (h_h + diag_h) t + g_h . t`` along ``s0 + t s``:
    ``a t^2 + b t + c`` (scipy's ``build_quadratic_1d``)."""
    hs = h_h @ s
    a = 0.5 * (np.dot(s, hs) + np.dot(s * diag_h, s))
    b = np.dot(g_h, s) + np.dot(s0, hs) + np.dot(s0 * diag_h, s)
    c = 0.5 * (np.dot(s0, h_h @ s0) + np.dot(s0 * diag_h, s0)) + np.dot(g_h, s0)
    return a, b, c


@njit(**_JIT)
def _quadratic(h_h, g_h, s, diag_h):
    return 0.5 * (np.dot(s, h_h @ s) + np.dot(s * diag_h, s)) + np.dot(g_h, s)


@njit(**_JIT)
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


@njit(**_JIT)
def _step_to_bound(x, s, lb, ub):
    """Largest ``t`` with ``x + t s`` in the box, and which coordinates reach it (signed)."""
    steps = np.full(x.size, np.inf)
    for i in range(x.size):
        if s[i] != 0:
            steps[i] = max((lb[i] - x[i]) / s[i], (ub[i] - x[i]) / s[i])
    t = np.min(steps)
    hits = np.zeros(x.size)
    for i in range(x.size):
        if steps[i] == t:
            hits[i] = np.sign(s[i])
    return t, hits


@njit(**_JIT)
def _intersect_sphere(x, s, delta):
    """Both ``t`` with ``||x + t s|| = delta``, ascending."""
    a, b, c = np.dot(s, s), np.dot(x, s), np.dot(x, x) - delta ** 2
    q = -(b + math.copysign(math.sqrt(b * b - a * c), b))
    t1, t2 = q / a, c / q
    return (t1, t2) if t1 < t2 else (t2, t1)


@njit(**_JIT)
def propose(x, h_h, diag_h, g_h, eig, vecs, sg, d, delta, alpha, lb, ub, theta):
    """One trial step: ``(x_new, step_norm, step_h_norm, predicted, alpha)``.

    The trust-region step if it stays in the box, else the best of its strictly feasible
    part, its reflection off the first bound hit, and the scaled gradient (scipy's
    ``select_step``); ``x_new`` is made strictly feasible as in scipy.
    """
    p_h, alpha = _trust_region_step(eig, vecs, sg, delta, alpha)
    p = d * p_h
    step, step_h, predicted = _select_step(x, h_h, diag_h, g_h, p, p_h, d, delta, lb, ub,
                                           theta)
    return (strictly_feasible(x + step, lb, ub), _norm(step), _norm(step_h), predicted,
            alpha)


@njit(**_JIT)
def _select_step(x, h_h, diag_h, g_h, p, p_h, d, delta, lb, ub, theta):
    inside = True
    for i in range(x.size):
        if not (lb[i] <= x[i] + p[i] <= ub[i]):
            inside = False
    if inside:
        return p, p_h, -_quadratic(h_h, g_h, p_h, diag_h)
    p_stride, hits = _step_to_bound(x, p, lb, ub)
    r_h = p_h.copy()
    for i in range(x.size):
        if hits[i] != 0:
            r_h[i] = -r_h[i]
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
        a, b, c = _quadratic_1d(h_h, g_h, r_h, diag_h, p_h)
        r_stride, r_value = _minimize_1d(a, b, r_lo, r_hi, c)
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
    a, b, _ = _quadratic_1d(h_h, g_h, ag_h, diag_h, np.zeros_like(ag_h))
    ag_stride, ag_value = _minimize_1d(a, b, 0.0, ag_stride, 0.0)
    if p_value < r_value and p_value < ag_value:
        return p, p_h, -p_value
    if r_value < p_value and r_value < ag_value:
        return r, r_h, -r_value
    return ag * ag_stride, ag_h * ag_stride, -ag_value
