"""The ``p x p`` arithmetic of one trust-region reflective iteration (:mod:`._trust_region`).

Each iteration of scipy's ``trf`` does a few dozen small-array operations; as NumPy calls on
``p ~ 10`` they cost ~0.2 ms of interpreter time, as much as a model run on thousands of
samples. Here they are a few calls:

* :func:`scaled_problem` (once per accepted point): the Coleman-Li scaling at ``x``, the scaled
  gradient and Gauss-Newton matrix (the compiled :func:`prepare`), ``R`` with ``R^T R = J^T J``
  and the SVD of ``[R diag(d); diag(diag_h)^(1/2)]``;
* :func:`propose` (compiled, once per trial point): Moré's trust-region step for a radius and
  scipy's ``select_step`` among it, its reflection and the scaled gradient.

The arithmetic is scipy's (``optimize/_lsq/trf.py`` and ``common.py``), and the same, bit
for bit, as when both steps were compiled whole. What changed is what numba compiles (issue 29:
the first fit after installing spent ~8 s of CPU compiling these two steps):

* the factorisations are LAPACK's ``potrf`` / ``gesdd`` / ``syevd`` called through scipy,
  the library and the arguments numba's ``np.linalg`` used; numba compiling its
  ``np.linalg`` wrappers cost most of that time, calling them here costs ~2 us per accepted
  point;
* every other whole-array operation is a loop or a small kernel (array expressions and
  NumPy reductions each cost numba a compiled loop nest), dot products stay BLAS's
  (``np.dot`` / ``@`` in one kernel each, so rounding is unchanged);
* ``propose`` does the step selection itself: numba emits a kernel's callees again into
  each caller, so every level of calls costs compile time.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit
from scipy.linalg import lapack

__all__ = ["coleman_li", "prepare", "propose", "scaled_problem", "square_root",
           "strictly_feasible"]

_EPS = np.finfo(float).eps
_JIT = {"cache": True, "error_model": "numpy"}


@njit(**_JIT)
def _dot(a, b):
    return np.dot(a, b)


@njit(**_JIT)
def _matvec(m, v):
    return m @ v


@njit(**_JIT)
def _norm(v):
    return math.sqrt(_dot(v, v))


@njit(**_JIT)
def coleman_li(x, g, lb, ub):
    """Coleman-Li scaling vector ``v`` and its derivative sign ``dv`` (scipy's
    ``CL_scaling_vector``)."""
    v, dv = np.ones(x.size), np.zeros(x.size)
    for i in range(x.size):
        if g[i] < 0 and math.isfinite(ub[i]):
            v[i], dv[i] = ub[i] - x[i], -1.0
        if g[i] > 0 and math.isfinite(lb[i]):
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


def _refuse_non_finite() -> None:
    # numba's np.linalg refused these too (the fit reports the error)
    raise np.linalg.LinAlgError("Array must not contain infs or NaNs.")


def square_root(jtj: np.ndarray) -> np.ndarray:
    """An ``R`` with ``R^T R = J^T J``: the Cholesky factor, else from the eigendecomposition
    (see the accuracy note in :mod:`._trust_region`)."""
    # potrf reads the lower triangle of C-ordered jtj (the upper one of its transpose), as
    # numba's np.linalg.cholesky did; a NaN or inf fails it (info > 0)
    factor, info = lapack.dpotrf(jtj.T, lower=0, clean=1)
    if info == 0:
        return np.ascontiguousarray(factor)
    if not np.isfinite(jtj).all():
        _refuse_non_finite()
    eig, vecs, info = lapack.dsyevd(jtj, compute_v=1, lower=1)
    if info != 0:
        raise np.linalg.LinAlgError("Eigenvalues did not converge")
    return np.sqrt(np.maximum(eig, 0.0)).reshape(-1, 1) * vecs.T


@functools.lru_cache(maxsize=16)
def _svd_workspace(m: int, n: int) -> int:
    """gesdd's optimal workspace for an ``m x n`` matrix (numba's query, the same path)."""
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
    d, diag_h, g_h, h_h, stacked, g_norm, finite = prepare(x, jtj, root, g, lb, ub, scale_inv)
    if not finite:
        _refuse_non_finite()
    _, sv, vecs_t, info = lapack.dgesdd(stacked, compute_uv=1, full_matrices=0,
                                        lwork=_svd_workspace(*stacked.shape), overwrite_a=1)
    if info != 0:
        raise np.linalg.LinAlgError("SVD did not converge")
    return (d, diag_h, g_h, h_h, sv ** 2, np.ascontiguousarray(vecs_t.T), vecs_t @ g_h,
            g_norm)


@njit(**_JIT)
def prepare(x, jtj, root, g, lb, ub, scale_inv):
    """:func:`scaled_problem` up to the SVD: ``(d, diag_h, g_h, h_h, stacked, g_norm,
    finite)``, ``stacked`` the matrix to decompose (Fortran order, as LAPACK takes it) and
    whether it is finite (``scale_inv`` raised in place)."""
    p = x.size
    for i in range(p):
        scale_inv[i] = max(scale_inv[i], math.sqrt(max(jtj[i, i], 0.0)))
    v, dv = coleman_li(x, g, lb, ub)
    g_norm = 0.0
    for i in range(p):
        a = abs(g[i] * v[i])
        if not math.isnan(g_norm) and not a <= g_norm:  # np.max's: a NaN stays
            g_norm = a
    for i in range(p):
        if dv[i] != 0:
            v[i] *= scale_inv[i]
    d, diag_h, g_h = np.empty(p), np.empty(p), np.empty(p)
    for i in range(p):
        d[i] = math.sqrt(v[i]) / scale_inv[i]
        diag_h[i] = g[i] * dv[i] / scale_inv[i]
        g_h[i] = d[i] * g[i]
    h_h = np.empty((p, p))
    stacked_t = np.zeros((p, 2 * p))
    for i in range(p):
        for j in range(p):
            h_h[i, j] = jtj[i, j] * (d[i] * d[j])
            stacked_t[j, i] = root[i, j] * d[j]
        stacked_t[i, p + i] = math.sqrt(diag_h[i])
    finite = True
    for i in range(p):
        for j in range(2 * p):
            finite = finite and math.isfinite(stacked_t[i, j])
    return d, diag_h, g_h, h_h, stacked_t.T, g_norm, finite


@njit(**_JIT)
def _scaled(a, c):
    out = np.empty(a.size)
    for i in range(a.size):
        out[i] = a[i] * c
    return out


@njit(**_JIT)
def _times(a, b):
    out = np.empty(a.size)
    for i in range(a.size):
        out[i] = a[i] * b[i]
    return out


@njit(**_JIT)
def _plus(a, b):
    out = np.empty(a.size)
    for i in range(a.size):
        out[i] = a[i] + b[i]
    return out


@njit(**_JIT)
def _step(vecs, sg, eig, alpha):
    """``-V (sg / (eig + alpha))``."""
    q = np.empty(eig.size)
    for j in range(eig.size):
        q[j] = sg[j] / (eig[j] + alpha)
    return _scaled(_matvec(vecs, q), -1.0)


@njit(**_JIT)
def _secular(sg, eig, alpha):
    """``||sg / (eig + alpha)||`` and ``sum(sg^2 / (eig + alpha)^3)``."""
    q = np.empty(eig.size)
    cubes = 0.0
    for i in range(eig.size):
        denom = eig[i] + alpha
        q[i] = sg[i] / denom
        cubes += sg[i] ** 2 / denom ** 3
    return _norm(q), cubes


@njit(**_JIT)
def _trust_region_step(eig, vecs, sg, delta, alpha):
    """Moré's solution of ``min ||J_h p + r||, ||p|| <= delta`` from ``M = V diag(eig) V^T``
    and ``sg = V^T g_h``; returns ``(p, alpha)`` (scipy's ``solve_lsq_trust_region``,
    ``rtol = 0.01``, ``max_iter = 10``)."""
    full_rank = eig[-1] ** 0.5 > _EPS * 2 * eig.size * eig[0] ** 0.5
    if full_rank:
        p = _step(vecs, sg, eig, 0.0)
        if _norm(p) <= delta:
            return p, 0.0
    alpha_upper = _norm(sg) / delta
    alpha_lower = 0.0
    if full_rank:
        p_norm, cubes = _secular(sg, eig, 0.0)
        phi = p_norm - delta
        phi_prime = -cubes / p_norm
        alpha_lower = -phi / phi_prime
    if not full_rank and alpha == 0:
        alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
    for _ in range(10):
        if alpha < alpha_lower or alpha > alpha_upper:
            alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
        p_norm, cubes = _secular(sg, eig, alpha)
        phi = p_norm - delta
        phi_prime = -cubes / p_norm
        if phi < 0:
            alpha_upper = alpha
        ratio = phi / phi_prime
        alpha_lower = max(alpha_lower, alpha - ratio)
        alpha -= (phi + delta) * ratio / delta
        if abs(phi) < 0.01 * delta:
            break
    p = _step(vecs, sg, eig, alpha)
    return _scaled(p, delta / _norm(p)), alpha


@njit(**_JIT)
def _quadratic_1d(h_h, g_h, s, diag_h, s0):
    """Coefficients of the model ``0.5 t^T (h_h + diag_h) t + g_h . t`` along ``s0 + t s``:
    ``a t^2 + b t + c`` (scipy's ``build_quadratic_1d``)."""
    hs = _matvec(h_h, s)
    a = 0.5 * (_dot(s, hs) + _dot(_times(s, diag_h), s))
    b = _dot(g_h, s) + _dot(s0, hs) + _dot(_times(s0, diag_h), s)
    c = 0.5 * (_dot(s0, _matvec(h_h, s0)) + _dot(_times(s0, diag_h), s0)) + _dot(g_h, s0)
    return a, b, c


@njit(**_JIT)
def _quadratic(h_h, g_h, s, diag_h):
    return 0.5 * (_dot(s, _matvec(h_h, s)) + _dot(_times(s, diag_h), s)) + _dot(g_h, s)


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
    t = math.inf
    for i in range(x.size):
        if s[i] != 0:
            t = min(t, max((lb[i] - x[i]) / s[i], (ub[i] - x[i]) / s[i]))
    hits = np.zeros(x.size)
    for i in range(x.size):
        if s[i] != 0 and max((lb[i] - x[i]) / s[i], (ub[i] - x[i]) / s[i]) == t:
            hits[i] = 1.0 if s[i] > 0 else -1.0
    return t, hits


@njit(**_JIT)
def _intersect_sphere(x, s, delta):
    """Both ``t`` with ``||x + t s|| = delta``, ascending."""
    a, b, c = _dot(s, s), _dot(x, s), _dot(x, x) - delta ** 2
    q = -(b + math.copysign(math.sqrt(b * b - a * c), b))
    t1, t2 = q / a, c / q
    return (t1, t2) if t1 < t2 else (t2, t1)


@njit(**_JIT)
def propose(x, h_h, diag_h, g_h, eig, vecs, sg, d, delta, alpha, lb, ub, theta):
    """One trial step: ``(x_new, step_norm, step_h_norm, predicted, alpha)``.

    The trust-region step if it stays in the box, else the best of its strictly feasible
    part, its reflection off the first bound hit, and the scaled gradient (scipy's
    ``select_step``); ``x_new`` is made strictly feasible as in scipy. One kernel, not a
    call of a ``select_step`` kernel: numba emits a kernel's callees again into each caller,
    so every level of calls costs compile time (issue 29). Not split either (the selection
    compiled only when a step leaves the box): the default mPL fit's steps do leave it, and
    the two kernels took 2.8 s to compile against this one's 2.4 s.
    """
    p_h, alpha = _trust_region_step(eig, vecs, sg, delta, alpha)
    p = _times(d, p_h)
    inside = True
    for i in range(x.size):
        if not (lb[i] <= x[i] + p[i] <= ub[i]):
            inside = False
    if inside:
        step, step_h, predicted = p, p_h, -_quadratic(h_h, g_h, p_h, diag_h)
    else:
        p_stride, hits = _step_to_bound(x, p, lb, ub)
        r_h = p_h.copy()
        for i in range(x.size):
            if hits[i] != 0:
                r_h[i] = -r_h[i]
        r = _times(d, r_h)
        p, p_h = _scaled(p, p_stride), _scaled(p_h, p_stride)
        _, to_tr = _intersect_sphere(p_h, r_h, delta)
        to_bound, _ = _step_to_bound(_plus(x, p), r, lb, ub)
        r_stride = min(to_bound, to_tr)
        if r_stride > 0:
            r_lo = (1 - theta) * p_stride / r_stride
            r_hi = theta * to_bound if r_stride == to_bound else to_tr
        else:
            r_lo, r_hi = 0.0, -1.0
        if r_lo <= r_hi:
            a, b, c = _quadratic_1d(h_h, g_h, r_h, diag_h, p_h)
            r_stride, r_value = _minimize_1d(a, b, r_lo, r_hi, c)
            r_h = _plus(_scaled(r_h, r_stride), p_h)
            r = _times(r_h, d)
        else:
            r_value = math.inf
        p, p_h = _scaled(p, theta), _scaled(p_h, theta)
        p_value = _quadratic(h_h, g_h, p_h, diag_h)
        ag_h = _scaled(g_h, -1.0)
        ag = _times(d, ag_h)
        to_tr = delta / _norm(ag_h)
        to_bound, _ = _step_to_bound(x, ag, lb, ub)
        ag_stride = theta * to_bound if to_bound < to_tr else to_tr
        a, b, _ = _quadratic_1d(h_h, g_h, ag_h, diag_h, np.zeros(x.size))
        ag_stride, ag_value = _minimize_1d(a, b, 0.0, ag_stride, 0.0)
        if p_value < r_value and p_value < ag_value:
            step, step_h, predicted = p, p_h, -p_value
        elif r_value < p_value and r_value < ag_value:
            step, step_h, predicted = r, r_h, -r_value
        else:
            step, step_h = _scaled(ag, ag_stride), _scaled(ag_h, ag_stride)
            predicted = -ag_value
    return (strictly_feasible(_plus(x, step), lb, ub), _norm(step), _norm(step_h), predicted,
            alpha)
