"""Compiled hot loops of the mPL model; ``model.py`` holds the readable reference and the checks.

All arrays are float64 and already validated by the caller. ``knee`` is the per-cell voltage
beyond which the resistor is linear with slope ``cap`` (eq. 5.29, see ``model.py``).

The runs, the blocks and the fit's pass advance a cell by :func:`cell_increment`: one ``exp``
per cell and sample (:func:`sinh_cosh`), the per-cell constants (:func:`cell_constants`) taken
out of the sample loop; those cell functions are in :mod:`.cell_kernels`. ``benchmarks/bench_kernels.py`` times them against the fastest plain C
of the same recursion (issue 29).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..._kernel_inputs import read_only
from .cell_kernels import (
    cell_constants,
    cell_increment,
    constants,
    current,
    sinh_cosh,
    sinh_series,
    straight_offset,
)


@njit(cache=True, inline="always")
def readout(w, v_b, x, u):
    """``w_0 u + sum w_k x_k - V_b`` (eq. 5.2; with mpl-poly's and mpl-g's ``g`` outside, eq.
    5.17), summed in this order by every run and block of the three families."""
    acc = w[0] * u - v_b
    for k in range(x.size):
        acc += w[k + 1] * x[k]
    return acc


@njit(cache=True, inline="always")
def input_for(w, v_b, x, z):
    """``(z + V_b - sum w_k x_k) / w_0``: the input whose :func:`readout` is ``z`` (eq. 5.13)."""
    acc = z + v_b
    for k in range(x.size):
        acc -= w[k + 1] * x[k]
    return acc / w[0]


# the cell's arithmetic lives in cell_kernels.py; its names stay importable from here
__all__ = ["NORMAL_BLOCK", "advance_cells", "advance_with_sensitivities",
           "block_forward", "block_inverse", "cell_constants", "cell_increment",
           "cell_sensitivity_step", "constants", "current", "fold_block", "input_for", "invert",
           "knee_constants", "mirror_upper", "normal_equations", "readout", "simulate",
           "simulate_with_jacobian", "sinh_cosh", "sinh_series", "straight_offset",
           "theta_cells", "theta_normal_equations"]


@njit(cache=True, inline="always")
def advance_cells(x, drive, inv_vt, two_i_s_dt, knee, c0, cap_dt):
    """One Euler step of every cell driven by ``drive`` (eq. 5.6), in place: the update of the
    runs of mpl and mpl-g, forward and inverse."""
    for k in range(x.size):
        x[k] += cell_increment(drive - x[k], inv_vt[k], two_i_s_dt[k], knee[k], c0[k], cap_dt)


@njit(cache=True)
def simulate(u, x0, i_s, v_t, w, v_b, knee, cap, dt):
    x = x0.copy()
    y = np.empty(u.size)
    inv_vt, two_i_s_dt, c0 = constants(i_s, v_t, knee, cap, dt)
    cap_dt = cap * dt
    for n in range(u.size):
        u_n = u[n]
        y[n] = readout(w, v_b, x, u_n)
        advance_cells(x, u_n, inv_vt, two_i_s_dt, knee, c0, cap_dt)
    return y, x


@njit(cache=True)
def invert(y, x0, i_s, v_t, w, v_b, knee, cap, dt):
    """Inverse model (eq. 5.13-5.14): output first, then state update (fig. 5.12).

    Returns the index of the first sample that left the finite range, or -1.
    """
    x = x0.copy()
    u_hat = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    inv_vt, two_i_s_dt, c0 = constants(i_s, v_t, knee, cap, dt)
    cap_dt = cap * dt
    for n in range(y.size):
        e = input_for(w, v_b, x, y[n])
        if not abs(e) < bound:
            return u_hat, x, n
        u_hat[n] = e
        advance_cells(x, e, inv_vt, two_i_s_dt, knee, c0, cap_dt)
    return u_hat, x, -1


@njit(cache=True, inline="always")
def cell_sensitivity_step(v, inv_vt, two_i_s_dt, two_i_s, g, knee, c0, f_knee, dvt_knee, cap,
                          cap_dt):
    """``(f dt, d f / d log G, d f / d log V_T, f')`` at ``v``; ``f dt`` is
    :func:`cell_increment`'s, in the same arithmetic, from the same ``exp``.

    Inside the knee ``df/dlog G = f`` and ``df/dlog V_T = f - v f'(v)``; on the straight
    continuation the knee's own dependence cancels because ``f'(knee) = cap``, leaving the same
    terms at the knee (``f_knee = f(knee)``, ``dvt_knee = f_knee - knee cap``).
    """
    if abs(v) <= knee:
        sh, ch = sinh_cosh(v * inv_vt)
        f = two_i_s * sh
        slope = g * ch
        return two_i_s_dt * sh, f, f - v * slope, slope
    if v > 0:
        return c0 + cap_dt * v, f_knee, dvt_knee, cap
    return -c0 + cap_dt * v, -f_knee, -dvt_knee, cap


# inline: a separate kernel costs its callers ~0.05 s more to compile (issue 29)
@njit(cache=True, inline="always")
def knee_constants(i_s, v_t, knee, cap):
    """Per cell ``2 I_S``, ``G = 2 I_S / V_T``, ``f(knee)`` and ``f(knee) - knee cap`` (one loop:
    numba compiles it in half the time of the same array expressions, issue 29)."""
    n = i_s.size
    two_i_s, g, f_knee, dvt_knee = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for k in range(n):
        two_i_s[k] = 2.0 * i_s[k]
        g[k] = 2.0 * i_s[k] / v_t[k]
        f_knee[k] = 2.0 * i_s[k] * np.sinh(knee[k] / v_t[k]) if knee[k] < np.inf else 0.0
        dvt_knee[k] = f_knee[k] - knee[k] * cap
    return two_i_s, g, f_knee, dvt_knee


@njit(cache=True, inline="always")
def advance_with_sensitivities(x, sens_g, sens_vt, drive, inv_vt, two_i_s_dt, two_i_s, g, knee,
                               c0, f_knee, dvt_knee, cap, cap_dt, dt):
    """:func:`advance_cells` (bit for bit: :func:`cell_sensitivity_step`) with each cell's
    sensitivities to ``log G_k`` and ``log V_Tk`` carried along, in place: the passes of the
    mpl and mpl-g fits."""
    for k in range(x.size):
        step, d_log_g, d_log_vt, slope = cell_sensitivity_step(
            drive - x[k], inv_vt[k], two_i_s_dt[k], two_i_s[k], g[k], knee[k], c0[k],
            f_knee[k], dvt_knee[k], cap, cap_dt)
        sens_g[k] += (d_log_g - slope * sens_g[k]) * dt
        sens_vt[k] += (d_log_vt - slope * sens_vt[k]) * dt
        x[k] += step


@njit(cache=True)
def simulate_with_jacobian(u, x0, i_s, v_t, w, v_b, knee, cap, dt):
    """Forward model output (:func:`simulate`'s, bit for bit) and its exact Jacobian by forward
    sensitivities (:func:`advance_with_sensitivities`).

    Columns follow ``MplParams.to_vector``: per cell ``log G_k`` and ``log V_Tk``
    (``G = 2 I_S / V_T``), then ``w_0 .. w_N`` and ``V_b``.
    """
    n_cells = x0.size
    x = x0.copy()
    sens_g, sens_vt = np.zeros(n_cells), np.zeros(n_cells)
    y = np.empty(u.size)
    jac = np.empty((u.size, 3 * n_cells + 2))
    inv_vt, two_i_s_dt, c0 = constants(i_s, v_t, knee, cap, dt)
    two_i_s, g, f_knee, dvt_knee = knee_constants(i_s, v_t, knee, cap)
    cap_dt = cap * dt
    for n in range(u.size):
        acc = w[0] * u[n] - v_b
        for k in range(n_cells):
            acc += w[k + 1] * x[k]
            jac[n, 2 * k] = w[k + 1] * sens_g[k]
            jac[n, 2 * k + 1] = w[k + 1] * sens_vt[k]
            jac[n, 2 * n_cells + 1 + k] = x[k]
        y[n] = acc
        jac[n, 2 * n_cells] = u[n]
        jac[n, 3 * n_cells + 1] = -1.0
        advance_with_sensitivities(x, sens_g, sens_vt, u[n], inv_vt, two_i_s_dt, two_i_s, g, knee,
                                   c0, f_knee, dvt_knee, cap, cap_dt, dt)
    return y, jac


# Rows of J gathered, column-major, before they are folded into J^T J: a block of 256 samples
# costs 256 x p x 8 bytes and keeps the fold's dot products in L1.
NORMAL_BLOCK = 256


@njit(cache=True, fastmath={"reassoc", "contract"})
def fold_block(cols, res, m, jtj, jtr):
    """Add ``C C^T`` (upper triangle) to ``jtj`` and ``C res`` to ``jtr`` for ``C = cols[:, :m]``.

    Contiguous dot products that the compiler vectorises (``reassoc``: summation order is free,
    as in BLAS); half the products of the full ``block.T @ block``, with no temporaries. Rows
    are taken in pairs against pairs (2 x 2 blocks: four products per four loads instead of
    one per two), which makes the fold about a third faster.
    """
    p = cols.shape[0]
    for i in range(p):
        ci = cols[i]
        acc = 0.0
        for t in range(m):
            acc += ci[t] * res[t]
        jtr[i] += acc
    for i in range(0, p - 1, 2):
        a, b = cols[i], cols[i + 1]
        aa = ab = bb = 0.0
        for t in range(m):
            aa += a[t] * a[t]
            ab += a[t] * b[t]
            bb += b[t] * b[t]
        jtj[i, i] += aa
        jtj[i, i + 1] += ab
        jtj[i + 1, i + 1] += bb
        for j in range(i + 2, p - 1, 2):
            c, d = cols[j], cols[j + 1]
            ac = ad = bc = bd = 0.0
            for t in range(m):
                ac += a[t] * c[t]
                ad += a[t] * d[t]
                bc += b[t] * c[t]
                bd += b[t] * d[t]
            jtj[i, j] += ac
            jtj[i, j + 1] += ad
            jtj[i + 1, j] += bc
            jtj[i + 1, j + 1] += bd
        if (p - i) % 2:  # an odd last column against this pair
            c = cols[p - 1]
            ac = bc = 0.0
            for t in range(m):
                ac += a[t] * c[t]
                bc += b[t] * c[t]
            jtj[i, p - 1] += ac
            jtj[i + 1, p - 1] += bc
    if p % 2:
        c = cols[p - 1]
        cc = 0.0
        for t in range(m):
            cc += c[t] * c[t]
        jtj[p - 1, p - 1] += cc


@njit(cache=True, inline="always")  # as knee_constants
def mirror_upper(a):
    """Copy the upper triangle of square ``a`` onto its lower triangle, in place."""
    for i in range(a.shape[0]):
        for j in range(i):
            a[i, j] = a[j, i]
    return a


@njit(cache=True)
def normal_equations(u, y_target, x0, i_s, v_t, w, v_b, knee, cap, dt):
    """``sum(r^2)``, ``J^T J`` and ``J^T r`` for ``r = y - y_target`` in one pass.

    The same forward sensitivities and column order as :func:`simulate_with_jacobian`, but
    the Jacobian rows are folded into the (p x p) and (p,) sums block by block as they are
    formed, so memory is independent of ``u.size``. The state and the outputs are
    :func:`simulate`'s, bit for bit (:func:`advance_with_sensitivities`), so ``sum(r^2)`` is the
    sequential sum of the squared residuals of :func:`simulate`.
    """
    n_cells = x0.size
    p = 3 * n_cells + 2
    x = x0.copy()
    sens_g, sens_vt = np.zeros(n_cells), np.zeros(n_cells)
    inv_vt, two_i_s_dt, c0 = constants(i_s, v_t, knee, cap, dt)
    two_i_s, g, f_knee, dvt_knee = knee_constants(i_s, v_t, knee, cap)
    cap_dt = cap * dt
    cols = np.empty((p, NORMAL_BLOCK))
    res = np.empty(NORMAL_BLOCK)
    jtj = np.zeros((p, p))
    jtr = np.zeros(p)
    sse = 0.0
    m = 0
    for n in range(u.size):
        acc = w[0] * u[n] - v_b
        for k in range(n_cells):
            acc += w[k + 1] * x[k]
            cols[2 * k, m] = w[k + 1] * sens_g[k]
            cols[2 * k + 1, m] = w[k + 1] * sens_vt[k]
            cols[2 * n_cells + 1 + k, m] = x[k]
        cols[2 * n_cells, m] = u[n]
        cols[3 * n_cells + 1, m] = -1.0
        r = acc - y_target[n]
        res[m] = r
        sse += r * r
        m += 1
        if m == NORMAL_BLOCK or n == u.size - 1:
            fold_block(cols, res, m, jtj, jtr)
            m = 0
        advance_with_sensitivities(x, sens_g, sens_vt, u[n], inv_vt, two_i_s_dt, two_i_s, g, knee,
                                   c0, f_knee, dvt_knee, cap, cap_dt, dt)
    return sse, mirror_upper(jtj), jtr


@njit(cache=True)
def theta_cells(theta, slope_cap, dt):
    """Rows ``i_s``, ``v_t`` and a third array ``knee`` of the cells at optimiser coordinates
    ``theta`` (``MplParams.to_vector``): ``MplParams.from_vector`` and ``model.knee_voltage``
    in the same arithmetic, without their validation (the fit's bounds keep ``theta`` in the
    domain)."""
    n_cells = (theta.size - 2) // 3
    resistors, knee = np.empty((2, n_cells)), np.empty(n_cells)
    for k in range(n_cells):
        v_t = np.exp(theta[2 * k + 1])
        i_s = 0.5 * np.exp(theta[2 * k]) * v_t
        ratio = slope_cap / (dt * (2 * i_s / v_t))
        knee[k] = v_t * np.arccosh(ratio) if ratio > 1 else 0.0
        resistors[0, k], resistors[1, k] = i_s, v_t
    return resistors, knee


def theta_normal_equations(u, y_target, x0, theta, slope_cap, dt):
    """:func:`normal_equations` at optimiser coordinates ``theta`` (:func:`theta_cells`; as
    NumPy calls the unpacking costs a tenth of a pass on short recordings, and a fit makes
    hundreds).

    Not a compiled caller of :func:`normal_equations`: numba would compile that pass a second
    time into it (~1.5 s of a cold first fit, issue 29). ``i_s``, ``v_t`` and ``w`` are passed
    read-only, as ``MplParams``' are, so that the fit's linear start and its passes share one
    specialisation of :func:`normal_equations`.
    """
    resistors, knee = theta_cells(theta, slope_cap, dt)
    n_cells = knee.size
    w = theta[2 * n_cells: 3 * n_cells + 1]
    return normal_equations(u, y_target, x0, read_only(resistors[0]), read_only(resistors[1]),
                            read_only(w),
                            theta[3 * n_cells + 1], knee, slope_cap / dt, dt)


# Loop blocks (protocol in ``hystkit.models._protocol``): body = [n, v_b, cap, dt,
# i_s (n), v_t (n), knee (n), w (n + 1)].

@njit(cache=True, inline="always")
def block_cells(body, x, xn, off, drive, ic):
    """The cells driven by ``drive`` (eq. 5.6), in :func:`simulate`'s arithmetic: the per-cell
    constants are recomputed per call in the same arithmetic (:func:`cell_constants`; the
    straight branch's offset only where it is taken), so a stream or a loop advances the state
    bit for bit as the offline run does. ``i_s``, ``v_t`` and ``knee`` follow each other from
    ``body[ic]`` (4 here, 13 in mpl-g's body)."""
    n = int(body[0])
    cap, dt = body[2], body[3]
    cap_dt = cap * dt
    for k in range(n):
        i_s, v_t, knee = body[ic + k], body[ic + n + k], body[ic + 2 * n + k]
        v = drive - x[off + k]
        c0 = 0.0 if abs(v) <= knee else straight_offset(i_s, v_t, knee, cap, dt)
        xn[off + k] = x[off + k] + cell_increment(v, 1.0 / v_t, 2.0 * i_s * dt, knee, c0, cap_dt)


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """``y = w_0 u + sum w_k x_k - V_b`` (eq. 5.2), then the cells driven by ``u`` (eq. 5.6)."""
    n = int(body[0])
    iw = 4 + 3 * n
    y = readout(body[iw:iw + n + 1], body[1], x[off:off + n], u)
    block_cells(body, x, xn, off, u, 4)
    return y


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """``u_hat = (y + V_b - sum w_k x_k) / w_0`` (eq. 5.13), cells driven by ``u_hat``."""
    n = int(body[0])
    iw = 4 + 3 * n
    u_hat = input_for(body[iw:iw + n + 1], body[1], x[off:off + n], y)
    block_cells(body, x, xn, off, u_hat, 4)
    return u_hat
