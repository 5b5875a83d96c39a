"""Compiled hot loops of the polynomial mPL; ``model.py`` holds the reference and the checks.

All arrays are float64 and validated by the caller. ``fc`` (N, 4) holds each cell resistor's
cubic coefficients ``c0..c3``, ``knees`` (N, 2) its points ``x-, x+`` where ``f' = s``
(``s = slope_cap / dt``); with ``limit`` the resistor is a straight line of slope ``s`` on
``v <= x-`` and ``v >= x+`` (eq. 5.29, corrected; ``x- == x+`` when ``f' >= s`` everywhere).
``gc`` (4,) holds the output resistor's cubic coefficients.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..mpl.kernels import NORMAL_BLOCK, fold_block, input_for, mirror_upper, readout


@njit(cache=True, inline="always")
def _cubic(c0, c1, c2, c3, x):
    """Value and slope of ``c0 + c1 x + c2 x^2 + c3 x^3``."""
    return c0 + x * (c1 + x * (c2 + x * c3)), c1 + x * (2.0 * c2 + 3.0 * c3 * x)


@njit(cache=True, inline="always")
def _cell(v, c, xm, xp, s, limit):
    """Limited cell-resistor current and its slope at ``v``; ``c`` is one row of ``fc``."""
    if limit and (v >= xp or v <= xm):
        x_b = xp if v >= xp else xm
        f_b, _ = _cubic(c[0], c[1], c[2], c[3], x_b)
        return f_b + s * (v - x_b), s
    return _cubic(c[0], c[1], c[2], c[3], v)


@njit(cache=True)
def cell_gradient(v, c, xm, xp, s, limit):
    """d f_lim(v) / d(c0, c1, c2, log c3) at fixed ``v``.

    Inside the knees (or without the limit) these are ``1, v, v^2, c3 v^3``. On a straight
    continuation the knee moves with the coefficients, but ``f'(knee) = s`` cancels that
    dependence, leaving the same terms at the knee. When ``f' >= s`` everywhere the line passes
    through the vertex ``x_v = -c2 / (3 c3)`` of ``f'``, where ``f'(x_v) > s``, so the vertex's
    own motion (``dx_v/dc2 = -1 / (3 c3)``, ``dx_v/dlog c3 = -x_v``) adds a term.
    """
    out = np.empty(4)
    if limit and (v >= xp or v <= xm):
        x_b = xp if v >= xp else xm
        out[0], out[1], out[2], out[3] = 1.0, x_b, x_b * x_b, c[3] * x_b ** 3
        if xm == xp:
            _, slope = _cubic(c[0], c[1], c[2], c[3], x_b)
            out[2] -= (slope - s) / (3.0 * c[3])
            out[3] -= (slope - s) * x_b
    else:
        out[0], out[1], out[2], out[3] = 1.0, v, v * v, c[3] * v ** 3
    return out


# No fastmath={"contract"} (fused multiply-add: 9.0 -> 7.2 ns/sample, 1 cell, the fast C 7.5):
# the stream's compiled block does not fuse alike, so the stream would lose its bit-for-bit
# check and fall back to the Python path (tests/live/test_stream_compiled.py).
@njit(cache=True)
def simulate(u, x0, fc, knees, s, limit, gc, w, v_b, dt, bound):
    """Forward model; returns ``(y, x_end, n_bad)``, ``n_bad`` the first sample whose state
    left ``|u_k| < bound`` (the unlimited model diverging) or -1."""
    n_cells = x0.size
    x = x0.copy()
    y = np.empty(u.size)
    for n in range(u.size):
        y[n], _ = _cubic(gc[0], gc[1], gc[2], gc[3], readout(w, v_b, x, u[n]))
        for k in range(n_cells):
            f, _ = _cell(u[n] - x[k], fc[k], knees[k, 0], knees[k, 1], s, limit)
            x[k] += f * dt
            if not abs(x[k]) < bound:
                return y, x, n
    return y, x, -1


@njit(cache=True, inline="always")
def output_columns(jac, n, col_g, col_w, col_vb, z, dg, u_n):
    """Row ``n`` of the Jacobian of ``y = g(z)``, ``z = w_0 u + sum w_k x_k - V_b``: the
    output resistor's coefficients ``g_0..g_3`` (``1, z, z^2, z^3``), ``w_0`` and ``V_b``;
    the cells' and ``w_1..w_N``'s columns are the caller's (mpl-poly and mpl-g)."""
    zj = 1.0
    for j in range(4):
        jac[n, col_g + j] = zj
        zj *= z
    jac[n, col_w] = dg * u_n
    jac[n, col_vb] = -dg


@njit(cache=True, inline="always")
def _advance_with_sensitivities(u_n, x, sens, fc, knees, s, limit, dt, bound):
    """The cells' Euler update driven by ``u_n`` with their parameter sensitivities (rows of
    ``sens``, the order of :func:`cell_gradient`); False as soon as a cell leaves
    ``|u_k| < bound``, the later cells then left as they were."""
    for k in range(x.size):
        v = u_n - x[k]
        f, slope = _cell(v, fc[k], knees[k, 0], knees[k, 1], s, limit)
        grad = cell_gradient(v, fc[k], knees[k, 0], knees[k, 1], s, limit)
        for j in range(4):
            sens[k, j] += (grad[j] - slope * sens[k, j]) * dt
        x[k] += f * dt
        if not abs(x[k]) < bound:
            return False
    return True


@njit(cache=True)
def simulate_with_jacobian(u, x0, sens0, fc, knees, s, limit, gc, w, v_b, dt, bound):
    """Forward model output and its exact Jacobian by forward sensitivities.

    Columns follow ``MplPolyParams.to_vector``: per cell ``c0, c1, c2, log c3``, then
    ``g0..g3``, ``w0..wN`` and ``V_b``. ``sens0`` (N, 4) is ``d u_k(0) / d(cell k params)``
    (non-zero when the start is at rest, which moves with the parameters).
    Returns ``(y, jac, n_bad)`` as :func:`simulate`.
    """
    n_cells = x0.size
    x = x0.copy()
    sens = sens0.copy()
    y = np.empty(u.size)
    jac = np.zeros((u.size, 5 * n_cells + 6))
    col_g, col_w, col_vb = 4 * n_cells, 4 * n_cells + 4, 5 * n_cells + 5
    for n in range(u.size):
        z = readout(w, v_b, x, u[n])
        y[n], dg = _cubic(gc[0], gc[1], gc[2], gc[3], z)
        output_columns(jac, n, col_g, col_w, col_vb, z, dg, u[n])
        for k in range(n_cells):
            jac[n, col_w + 1 + k] = dg * x[k]
            for j in range(4):
                jac[n, 4 * k + j] = dg * w[k + 1] * sens[k, j]
        if not _advance_with_sensitivities(u[n], x, sens, fc, knees, s, limit, dt, bound):
            return y, jac, n
    return y, jac, -1


# Jacobian rows gathered, column-major, and folded into J^T J block by block: NORMAL_BLOCK and
# fold_block are the mPL's.


@njit(cache=True)
def normal_equations(u, y_target, x0, sens0, fc, knees, s, limit, gc, w, v_b, dt, bound):
    """``sum(r^2)``, ``J^T J``, ``J^T r`` for ``r = y - y_target`` in one pass, with the
    sensitivities and column order of :func:`simulate_with_jacobian` but without storing ``J``.
    Returns ``(sse, jtj, jtr, n_bad)``, ``n_bad`` as :func:`simulate` (the sums then stop)."""
    n_cells = x0.size
    p = 5 * n_cells + 6
    x = x0.copy()
    sens = sens0.copy()
    cols = np.zeros((p, NORMAL_BLOCK))
    res = np.empty(NORMAL_BLOCK)
    jtj = np.zeros((p, p))
    jtr = np.zeros(p)
    sse = 0.0
    m = 0
    col_g, col_w, col_vb = 4 * n_cells, 4 * n_cells + 4, 5 * n_cells + 5
    rows = cols.T  # the block's Jacobian rows, as output_columns writes them
    for n in range(u.size):
        z = readout(w, v_b, x, u[n])
        y, dg = _cubic(gc[0], gc[1], gc[2], gc[3], z)
        output_columns(rows, m, col_g, col_w, col_vb, z, dg, u[n])
        for k in range(n_cells):
            cols[col_w + 1 + k, m] = dg * x[k]
            for j in range(4):
                cols[4 * k + j, m] = dg * w[k + 1] * sens[k, j]
        r = y - y_target[n]
        res[m] = r
        sse += r * r
        m += 1
        if m == NORMAL_BLOCK or n == u.size - 1:
            fold_block(cols, res, m, jtj, jtr)
            m = 0
        if not _advance_with_sensitivities(u[n], x, sens, fc, knees, s, limit, dt, bound):
            return sse, mirror_upper(jtj), jtr, n
    return sse, mirror_upper(jtj), jtr, -1


@njit(cache=True)
def solve_output(i, gc, lo, hi, sign, centre):
    """The ``z`` in ``[lo, hi]`` (a monotone branch of ``g`` around ``centre``, ``sign`` = sign
    of ``g'`` there) with ``g(z) = i``: safeguarded Newton inside a bisection bracket. Returns
    ``(z, ok)``; ``ok`` is False when ``i`` is outside the branch's range."""
    width = 1.0
    a = lo if np.isfinite(lo) else centre - width
    h_a = sign * (_cubic(gc[0], gc[1], gc[2], gc[3], a)[0] - i)
    while h_a > 0:
        if np.isfinite(lo) or width > 1e15:
            return np.nan, False
        width *= 2.0
        a = centre - width
        h_a = sign * (_cubic(gc[0], gc[1], gc[2], gc[3], a)[0] - i)
    width = 1.0
    b = hi if np.isfinite(hi) else centre + width
    h_b = sign * (_cubic(gc[0], gc[1], gc[2], gc[3], b)[0] - i)
    while h_b < 0:
        if np.isfinite(hi) or width > 1e15:
            return np.nan, False
        width *= 2.0
        b = centre + width
        h_b = sign * (_cubic(gc[0], gc[1], gc[2], gc[3], b)[0] - i)
    # Start from the linear-part guess so the answer depends on this sample only.
    z = (i - gc[0]) / gc[1] if gc[1] != 0.0 else np.nan
    if not a < z < b:
        z = 0.5 * (a + b)
    for _ in range(200):
        g, dg = _cubic(gc[0], gc[1], gc[2], gc[3], z)
        h = sign * (g - i)
        if h == 0.0:
            break
        if h < 0:
            a = z
        else:
            b = z
        z_new = z - (g - i) / dg if dg != 0.0 else np.nan
        if not a < z_new < b:
            z_new = 0.5 * (a + b)
        if abs(z_new - z) <= 4e-16 * (1.0 + abs(z)) or b - a <= 4e-16 * (1.0 + abs(z)):
            z = z_new
            break
        z = z_new
    return z, True


@njit(cache=True, inline="always")
def branch_input(y, gc, lo, hi, sign, centre, w, v_b, x, bound):
    """One sample of the inverse's input: ``z = g^-1(y)`` on the branch (:func:`solve_output`),
    then ``e = (z + V_b - sum w_k x_k) / w_0`` from the present state. Returns ``(e, why)``,
    ``why`` 1 when ``y`` is outside the branch's range, 2 when ``|e| >= bound``, else 0."""
    z, ok = solve_output(y, gc, lo, hi, sign, centre)
    if not ok:
        return 0.0, 1
    e = input_for(w, v_b, x, z)
    if not abs(e) < bound:
        return e, 2
    return e, 0


@njit(cache=True)
def invert(y, x0, fc, knees, s, limit, gc, lo, hi, sign, centre, w, v_b, dt, bound):
    """Inverse model: solve ``g(z) = i``, then ``e`` from the output equation with the present
    state, then the state update (order of fig. 5.12). Returns ``(e_hat, x_end, n_bad, why)``
    with ``why`` 1 when ``i`` is outside the range of the branch of ``g``, 2 when the estimate
    left ``|e| < bound``, and ``n_bad = -1`` when all went well."""
    n_cells = x0.size
    x = x0.copy()
    e_hat = np.empty(y.size)
    for n in range(y.size):
        e, why = branch_input(y[n], gc, lo, hi, sign, centre, w, v_b, x, bound)
        if why:
            return e_hat, x, n, why
        e_hat[n] = e
        for k in range(n_cells):
            f, _ = _cell(e - x[k], fc[k], knees[k, 0], knees[k, 1], s, limit)
            x[k] += f * dt
    return e_hat, x, -1, 0


# Loop blocks (protocol in ``hystkit.models._protocol``): body = [n, v_b, s, dt, limit,
# lo, hi, sign, centre, g0..g3, fc (N x 4, row-major), knees (N x 2), w (N + 1)]; ``lo, hi,
# sign, centre`` (``model.inverse_branch``) are read by the inverse only.
_IG = 9  # first output-resistor coefficient
_IF = 13  # first cell coefficient


@njit(cache=True, inline="always")
def _block_cells(body, x, xn, off, drive):
    """The cells' Euler update (eq. 5.6 with eq. 5.16, 5.29) driven by ``drive``."""
    n = int(body[0])
    ik = _IF + 4 * n
    limit = body[4] != 0.0
    for k in range(n):
        f, _ = _cell(drive - x[off + k], body[_IF + 4 * k:_IF + 4 * k + 4], body[ik + 2 * k],
                     body[ik + 2 * k + 1], body[2], limit)
        xn[off + k] = x[off + k] + f * body[3]


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """``y = g(w_0 u + sum w_k x_k - V_b)`` (eq. 5.17), then the cells driven by ``u``."""
    n = int(body[0])
    iw = _IF + 6 * n
    z = readout(body[iw:iw + n + 1], body[1], x[off:off + n], u)
    y, _ = _cubic(body[_IG], body[_IG + 1], body[_IG + 2], body[_IG + 3], z)
    _block_cells(body, x, xn, off, u)
    return y


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """``z = g^-1(y)`` on the rest branch (as :func:`invert`), ``u_hat = (z - sum w_k x_k +
    V_b) / w_0``, cells driven by ``u_hat``. NaN (output and state) when ``y`` is outside the
    branch's range: no input gives that output, and the loop stops on it."""
    n = int(body[0])
    iw = _IF + 6 * n
    z, ok = solve_output(y, body[_IG:_IG + 4], body[5], body[6], body[7], body[8])
    u_hat = input_for(body[iw:iw + n + 1], body[1], x[off:off + n], z) if ok else np.nan
    _block_cells(body, x, xn, off, u_hat)
    return u_hat
