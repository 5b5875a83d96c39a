"""Compiled hot loops of the Power-Law model; ``model.py`` holds the readable reference.

All arrays are float64 and already validated by the caller. Per cell ``k`` (0-based here, cell
``k + 1`` of the document) ``thr[k] = (k + 1) V_T`` is the threshold of eq. 2.16 and ``knee[k]``
(<= ``thr[k]``) the voltage where the power law hands over to the straight branch of slope
``g_lin`` (see ``model.py``). ``brk`` holds the M + 1 breakpoints of the output basis (eq. 2.17).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _scale_dt(i_t, power, dt):
    """``I_T / (p - 1) dt``: the power law's factor (eq. 2.16) times the Euler step."""
    return i_t / (power - 1.0) * dt


@njit(cache=True, inline="always")
def _straight_offset(scale_dt, thr, knee, power, g_dt):
    """``c0 = (scale (knee / thr)^p - g_lin knee) dt``, with which the straight branch beyond
    the knee is ``d dt = s c0 + g_lin dt v`` (``s`` the sign of ``v``); 0 without a knee."""
    return scale_dt * (knee * (1.0 / thr)) ** power - g_dt * knee if knee < np.inf else 0.0


@njit(cache=True, inline="always")
def _increment(v, inv_thr, scale_dt, knee, power, c0, g_dt):
    """``d(v) dt``, the cell's Euler increment: odd power law inside the knee (eq. 2.16),
    straight line outside.

    ``1 / thr``, ``scale_dt``, ``c0`` and ``g_dt`` do not change per sample: the runs compute
    them once per cell, the blocks per call in the same arithmetic (``c0`` only where the
    straight branch is taken), so both give the same bits. Beyond the knee the recursion's
    dependency chain is two operations, not six (most samples of fitted models are there).
    """
    a = abs(v)
    if a <= knee:
        return math.copysign(scale_dt * (a * inv_thr) ** power, v)
    return (c0 if v >= 0 else -c0) + g_dt * v


@njit(cache=True)
def _constants(i_t, thr, knee, power, g_lin, dt):
    """Per cell ``1 / thr`` and ``c0`` (:func:`_straight_offset`), and ``scale dt``,
    ``g_lin dt``."""
    scale_dt, g_dt = _scale_dt(i_t, power, dt), g_lin * dt
    inv_thr, c0 = np.empty(thr.size), np.empty(thr.size)
    for k in range(thr.size):
        inv_thr[k] = 1.0 / thr[k]
        c0[k] = _straight_offset(scale_dt, thr[k], knee[k], power, g_dt)
    return inv_thr, c0, scale_dt, g_dt


@njit(cache=True, inline="always")
def _f_inverse(u, brk, a):
    """``i = f^-1(u)`` for the increasing PWL ``f = sum a_j phi_j`` with ``f(0) = 0`` (eq. 2.18)."""
    m = a.size
    # f at the left end of each segment, accumulated from i = 0 (phi_j(0) = 0)
    j0 = 0
    while j0 < m - 1 and brk[j0 + 1] <= 0.0:
        j0 += 1
    # walk right or left from the segment that holds i = 0
    j, f_left, i_left = j0, 0.0, 0.0
    if u >= 0.0:
        while j < m - 1 and f_left + a[j] * (brk[j + 1] - i_left) < u:
            f_left += a[j] * (brk[j + 1] - i_left)
            i_left = brk[j + 1]
            j += 1
        return i_left + (u - f_left) / a[j]
    while j > 0 and f_left - a[j] * (i_left - brk[j]) > u:
        f_left -= a[j] * (i_left - brk[j])
        i_left = brk[j]
        j -= 1
    return i_left + (u - f_left) / a[j]


@njit(cache=True, inline="always")
def _f(i, brk, a):
    """``u = f(i) = sum_j a_j phi_j(i)`` with ``phi_j(i) = clip(i, b_j-1, b_j) - clip(0, ...)``,
    the outermost segments unbounded (eq. 2.17)."""
    m = a.size
    total = 0.0
    for j in range(m):
        lo = -np.inf if j == 0 else brk[j]
        hi = np.inf if j == m - 1 else brk[j + 1]
        total += a[j] * (min(max(i, lo), hi) - min(max(0.0, lo), hi))
    return total


@njit(cache=True)
def states(u, x0, i_t, thr, knee, power, g_lin, dt):
    """Cell voltages seen at each sample (before that sample's update), shape (n, N)."""
    n_cells = x0.size
    x = x0.copy()
    out = np.empty((u.size, n_cells))
    inv_thr, c0, scale_dt, g_dt = _constants(i_t, thr, knee, power, g_lin, dt)
    for n in range(u.size):
        for k in range(n_cells):
            out[n, k] = x[k]
            x[k] += _increment(u[n] - x[k], inv_thr[k], scale_dt, knee[k], power, c0[k], g_dt)
    return out, x


@njit(cache=True)
def simulate(u, x0, i_t, thr, knee, power, g_lin, dt, w, v_b, brk, a):
    n_cells = x0.size
    x = x0.copy()
    y = np.empty(u.size)
    inv_thr, c0, scale_dt, g_dt = _constants(i_t, thr, knee, power, g_lin, dt)
    for n in range(u.size):
        acc = w[0] * u[n] - v_b
        for k in range(n_cells):
            acc += w[k + 1] * x[k]
        y[n] = _f_inverse(acc, brk, a)
        for k in range(n_cells):
            x[k] += _increment(u[n] - x[k], inv_thr[k], scale_dt, knee[k], power, c0[k], g_dt)
    return y, x


@njit(cache=True)
def invert(y, x0, i_t, thr, knee, power, g_lin, dt, w, v_b, brk, a):
    """Inverse model (eq. 2.20 after ``u = f(i)``): output first, then the state update.

    Returns the index of the first sample that left the finite range, or -1.
    """
    n_cells = x0.size
    x = x0.copy()
    e_hat = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    inv_thr, c0, scale_dt, g_dt = _constants(i_t, thr, knee, power, g_lin, dt)
    for n in range(y.size):
        acc = _f(y[n], brk, a) + v_b
        for k in range(n_cells):
            acc -= w[k + 1] * x[k]
        e = acc / w[0]
        if not abs(e) < bound:
            return e_hat, x, n
        e_hat[n] = e
        for k in range(n_cells):
            x[k] += _increment(e - x[k], inv_thr[k], scale_dt, knee[k], power, c0[k], g_dt)
    return e_hat, x, -1


# Loop blocks (protocol in ``hystkit.models._protocol``): body = [n, m, i_t, power, g_lin, dt,
# v_b, thr (N), knee (N), w (N + 1), brk (M + 1), a (M)].

@njit(cache=True, inline="always")
def _block_cells(body, x, xn, off, drive):
    """The cells' Euler update driven by ``drive`` (eq. 2.16 with the straight branches), in
    the runs' arithmetic (:func:`_increment`)."""
    n = int(body[0])
    power, dt = body[3], body[5]
    scale_dt, g_dt = _scale_dt(body[2], power, dt), body[4] * dt
    for k in range(n):
        thr, knee = body[7 + k], body[7 + n + k]
        v = drive - x[off + k]
        c0 = 0.0 if abs(v) <= knee else _straight_offset(scale_dt, thr, knee, power, g_dt)
        xn[off + k] = x[off + k] + _increment(v, 1.0 / thr, scale_dt, knee, power, c0, g_dt)


@njit(cache=True, inline="always")
def _block_output_basis(body):
    """Slices of ``body``: the weights ``w``, the breakpoints and the slopes ``a``."""
    n, m = int(body[0]), int(body[1])
    iw = 7 + 2 * n
    ib = iw + n + 1
    return body[iw:ib], body[ib:ib + m + 1], body[ib + m + 1:ib + 2 * m + 1]


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """``i = f^-1(w_0 e + sum w_k u_k - V_b)`` (eq. 2.18), then the cells driven by ``e``."""
    w, brk, a = _block_output_basis(body)
    acc = w[0] * u - body[6]
    for k in range(w.size - 1):
        acc += w[k + 1] * x[off + k]
    y = _f_inverse(acc, brk, a)
    _block_cells(body, x, xn, off, u)
    return y


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """``e = (f(i) + V_b - sum w_k u_k) / w_0`` (eq. 2.17, 2.20), the cells driven by ``e``."""
    w, brk, a = _block_output_basis(body)
    acc = _f(y, brk, a) + body[6]
    for k in range(w.size - 1):
        acc -= w[k + 1] * x[off + k]
    e = acc / w[0]
    _block_cells(body, x, xn, off, e)
    return e
