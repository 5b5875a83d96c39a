"""Compiled hot loops of the ch. 7 compensator; ``model.py`` holds the reference and the checks.

All arrays are float64 and validated by the caller. The cells are the mPL's, advanced as the
mPL's runs advance them (``cell_increment``: the limited sinh resistor, eq. 5.1 with 5.29, one
``exp`` per cell, the per-cell ``constants`` out of the sample loop); the inverse of the output
resistor is the mpl-poly's (``solve_output``); ``gc`` (4,) holds ``g``'s cubic coefficients.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..mpl.kernels import (
    advance_cells,
    advance_with_sensitivities,
    block_cells,
    constants,
    input_for,
    knee_constants,
    readout,
)
from ..mpl_poly.kernels import branch_input, output_columns, solve_output


@njit(cache=True, inline="always")
def _output(gc, z):
    """``g(z)`` and ``g'(z)`` (eq. 5.16-5.17)."""
    return (gc[0] + z * (gc[1] + z * (gc[2] + z * gc[3])),
            gc[1] + z * (2.0 * gc[2] + 3.0 * gc[3] * z))


@njit(cache=True)
def simulate(u, x0, gc, w, v_b, i_s, v_t, knee, cap, dt):
    """Forward model; returns ``(y, x_end)``."""
    x = x0.copy()
    y = np.empty(u.size)
    inv_vt, two_i_s_dt, c0 = constants(i_s, v_t, knee, cap, dt)
    cap_dt = cap * dt
    for n in range(u.size):
        y[n], _ = _output(gc, readout(w, v_b, x, u[n]))
        advance_cells(x, u[n], inv_vt, two_i_s_dt, knee, c0, cap_dt)
    return y, x


@njit(cache=True)
def simulate_with_jacobian(u, x0, gc, w, v_b, i_s, v_t, knee, cap, dt):
    """Forward model output and its exact Jacobian by forward sensitivities.

    Columns follow ``MplGParams.to_vector``: per cell ``log G_k``, ``log V_Tk``, then
    ``g_0..g_3``, ``w_0..w_N``, ``V_b``. The cells' sensitivities are the mPL's (see
    ``mpl.kernels.advance_with_sensitivities``); the output multiplies them by ``g'(z)``.
    """
    n_cells = x0.size
    x = x0.copy()
    sens_g, sens_vt = np.zeros(n_cells), np.zeros(n_cells)
    y = np.empty(u.size)
    jac = np.empty((u.size, 3 * n_cells + 6))
    col_g, col_w, col_vb = 2 * n_cells, 2 * n_cells + 4, 3 * n_cells + 5
    inv_vt, two_i_s_dt, c0 = constants(i_s, v_t, knee, cap, dt)
    two_i_s, g, f_knee, dvt_knee = knee_constants(i_s, v_t, knee, cap)
    cap_dt = cap * dt
    for n in range(u.size):
        z = readout(w, v_b, x, u[n])
        y[n], dg = _output(gc, z)
        output_columns(jac, n, col_g, col_w, col_vb, z, dg, u[n])
        for k in range(n_cells):
            jac[n, 2 * k] = dg * w[k + 1] * sens_g[k]
            jac[n, 2 * k + 1] = dg * w[k + 1] * sens_vt[k]
            jac[n, col_w + 1 + k] = dg * x[k]
        # the state as simulate's, bit for bit
        advance_with_sensitivities(x, sens_g, sens_vt, u[n], inv_vt, two_i_s_dt, two_i_s, g, knee,
                                   c0, f_knee, dvt_knee, cap, cap_dt, dt)
    return y, jac


@njit(cache=True)
def invert(y, x0, gc, lo, hi, sign, centre, w, v_b, i_s, v_t, knee, cap, dt, bound):
    """Inverse model: ``g(z) = y`` on the branch, ``e`` from the output equation with the
    present state, then the state update (fig. 5.12). Returns ``(e_hat, x_end, n_bad, why)``:
    ``why`` 1 when ``y`` is outside the branch's range, 2 when ``|e| >= bound``; ``n_bad = -1``
    when all went well."""
    x = x0.copy()
    e_hat = np.empty(y.size)
    inv_vt, two_i_s_dt, c0 = constants(i_s, v_t, knee, cap, dt)
    cap_dt = cap * dt
    for n in range(y.size):
        e, why = branch_input(y[n], gc, lo, hi, sign, centre, w, v_b, x, bound)
        if why:
            return e_hat, x, n, why
        e_hat[n] = e
        advance_cells(x, e, inv_vt, two_i_s_dt, knee, c0, cap_dt)
    return e_hat, x, -1, 0


# Loop blocks (protocol in ``hystkit.models._protocol``): body = [n, v_b, cap, dt, 1.0, lo, hi,
# sign, centre, g0..g3, i_s (n), v_t (n), knee (n), w (n + 1)]. The head is the mpl-poly's
# layout (slot 4 is its limit switch, always on here), so that its ``solve_output`` and its C
# translation read ``lo, hi, sign, centre`` and ``g`` from the same places.
_IG = 9  # first output-resistor coefficient
_IC = 13  # first cell parameter


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """``y = g(w_0 u + sum w_k x_k - V_b)`` (eq. 5.17), then the cells driven by ``u`` (eq. 5.6,
    sinh resistors limited by eq. 5.29, as ``mpl.kernels``' blocks advance them)."""
    n = int(body[0])
    iw = _IC + 3 * n
    y, _ = _output(body[_IG:_IG + 4], readout(body[iw:iw + n + 1], body[1], x[off:off + n], u))
    block_cells(body, x, xn, off, u, _IC)
    return y


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """``z = g^-1(y)`` on the rest branch, ``u_hat = (z - sum w_k x_k + V_b) / w_0``, cells
    driven by ``u_hat``. NaN (output and state) when ``y`` is outside the branch's range: no
    input gives that output, and the loop stops on it."""
    n = int(body[0])
    iw = _IC + 3 * n
    z, ok = solve_output(y, body[_IG:_IG + 4], body[5], body[6], body[7], body[8])
    u_hat = input_for(body[iw:iw + n + 1], body[1], x[off:off + n], z) if ok else np.nan
    block_cells(body, x, xn, off, u_hat, _IC)
    return u_hat
