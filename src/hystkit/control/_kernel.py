"""The closed loop as one compiled kernel: every block, every step, no Python per sample.

``_loop.py`` holds the validating wrapper and the readable plain-Python reference that this
kernel must match. Arrays are float64 and validated by the caller.

State vector (explicit, in and out)::

    0 plant position [m]      1 plant velocity [m/s]
    2 PID integral            3 PID previous error      4 PID derivative term
    5 plant-estimate position 6 plant-estimate velocity (fig. 7.11, nominal plant)
    7-9 DOB estimates of position, velocity, input force (sec. 7.4)
    then the cells of S_r, of the compensator and of S_m

Signals recorded per step (rows of ``out``): see :data:`SIGNALS`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..models._mpl_poly_kernels import _cell, _cubic, solve_output
from ..models.mpl.kernels import current as _current
from ._sensors import BLOCK_HEADER

N_FIXED = 10
SIGNALS = ("y", "s", "y_hat", "s_hat", "y_hat_plant", "e", "u", "d_hat")
STOP_REASONS = {1: "plant position non-finite or beyond the position limit",
                2: "control effort non-finite",
                3: "sensor, model or compensator signal non-finite"}


@njit(cache=True)
def _poly_block(blk, x, xn, off, u):
    """Polynomial mPL step in normalised units (layout: ``_poly.pack_body``).

    Forward: ``y = g(w0 u + sum w_k x_k - V_b)`` (eq. 5.17), cells driven by ``u``. Inverse:
    ``z = g^-1(u)`` on the rest branch (safeguarded Newton, as ``mpl_poly.invert``), ``u_hat =
    (z - sum w_k x_k + V_b) / w0``, cells driven by ``u_hat``; NaN if ``u`` is outside the
    branch's range (the loop then stops).
    """
    n = int(blk[0])
    h = BLOCK_HEADER
    limit = blk[h] != 0.0
    ig, i_f = h + 5, h + 9
    ik, iw = i_f + 4 * n, i_f + 6 * n
    if blk[1] == 0.0:
        z = blk[iw] * u - blk[2]
        for k in range(n):
            z += blk[iw + 1 + k] * x[off + k]
        out, _ = _cubic(blk[ig], blk[ig + 1], blk[ig + 2], blk[ig + 3], z)
        drive = u
    else:
        z, ok = solve_output(u, blk[ig:ig + 4], blk[h + 1], blk[h + 2], blk[h + 3], blk[h + 4])
        acc = z + blk[2]
        for k in range(n):
            acc -= blk[iw + 1 + k] * x[off + k]
        out = acc / blk[iw] if ok else np.nan
        drive = out
    for k in range(n):
        f, _ = _cell(drive - x[off + k], blk[i_f + 4 * k:i_f + 4 * k + 4], blk[ik + 2 * k],
                     blk[ik + 2 * k + 1], blk[3], limit)
        xn[off + k] = x[off + k] + f * blk[4]
    return out


@njit(cache=True, inline="always")
def _block(blk, x, xn, off, u_in):
    """One mPL block step: output from ``x``, next cell states written to ``xn``.

    Forward: ``y = w0 u + sum w_k x_k - V_b`` (eq. 5.2), cells driven by ``u``. Inverse:
    ``u_hat = (y + V_b - sum w_k x_k) / w0`` (eq. 5.13), cells driven by ``u_hat`` (fig. 5.12).
    The polynomial mPL (``blk[9] == 1``) is :func:`_poly_block`.
    """
    n = int(blk[0])
    h = BLOCK_HEADER
    iw = h + 3 * n
    u = blk[5] * u_in + blk[6]
    if blk[9] != 0.0:
        return blk[7] * _poly_block(blk, x, xn, off, u) + blk[8]
    if blk[1] == 0.0:
        acc = blk[iw] * u - blk[2]
        for k in range(n):
            acc += blk[iw + 1 + k] * x[off + k]
        out = acc
        drive = u
    else:
        acc = u + blk[2]
        for k in range(n):
            acc -= blk[iw + 1 + k] * x[off + k]
        out = acc / blk[iw]
        drive = out
    for k in range(n):
        f, _ = _current(drive - x[off + k], blk[h + k], blk[h + n + k], blk[h + 2 * n + k],
                        blk[3])
        xn[off + k] = x[off + k] + f * blk[4]
    return blk[7] * out + blk[8]


@njit(cache=True)
def run(r, d_out, d_in, noise, x0, direct, plant, pid, dob, y_limit, blk_r, blk_c, blk_m):
    """Simulate ``r.size`` steps; stop at the first non-finite or out-of-range value.

    Parameters
    ----------
    r, d_out, d_in, noise : arrays, shape (n,)
        Reference [m], output disturbance [m], input force disturbance [N], sensor noise.
    x0 : array
        Initial state (layout in the module docstring).
    direct : bool
        Scheme (a) ``e = r - y_hat`` (fig. 7.1) if true, else scheme (b)
        ``e = g_s (S_m(r) - s)`` (fig. 7.8).
    plant : array
        ``[Ts, Ts^2/(2m), Ts/m, Ts^2/(2 m_n), Ts/m_n, u_max]``.
    pid : array
        ``[Kp, Ts/Ti, Td, Tf, anti_windup, g_s]``.
    dob : array
        ``[use, L_0, L_1, L_2]`` (predictor gains of the extended-state observer).
    blk_r, blk_c, blk_m : arrays
        Packed S_r, compensator (empty if absent) and S_m (empty if absent).

    Returns
    -------
    out : array, shape (8, n)
        Signals; only the first ``n_done`` columns are filled.
    x : array
        State after ``n_done`` steps.
    n_done : int
    reason : int
        0 if all steps ran, else a key of :data:`STOP_REASONS`.
    """
    n_steps = r.size
    out = np.zeros((8, n_steps))
    x = x0.copy()
    xn = x0.copy()
    ts, b1, b2, b1n, b2n, u_max = plant[0], plant[1], plant[2], plant[3], plant[4], plant[5]
    kp, ki, td, tf, anti_windup, g_s = pid[0], pid[1], pid[2], pid[3], pid[4] != 0.0, pid[5]
    use_dob = dob[0] != 0.0
    has_c = blk_c.size > 0
    has_m = blk_m.size > 0
    off_r = N_FIXED
    off_c = off_r + int(blk_r[0])
    off_m = off_c + (int(blk_c[0]) if has_c else 0)
    for n in range(n_steps):
        for i in range(x.size):
            xn[i] = x[i]
        y = x[0] + d_out[n]
        s = _block(blk_r, x, xn, off_r, y) + noise[n]
        y_hat = _block(blk_c, x, xn, off_c, s) if has_c else 0.0
        s_hat = _block(blk_m, x, xn, off_m, r[n]) if has_m else 0.0
        e = r[n] - y_hat if direct else g_s * (s_hat - s)
        # eq. 7.2: backward-difference derivative (optionally filtered, backward Euler)
        if tf == 0.0:
            d = td / ts * (e - x[3])
        else:
            d = (tf * x[4] + td * (e - x[3])) / (tf + ts)
        u_wanted = kp * (e + x[2] + d) - (x[9] if use_dob else 0.0)
        u = min(max(u_wanted, -u_max), u_max)
        # clamping anti-windup: freeze the integral while it pushes further into saturation
        frozen = anti_windup and u != u_wanted and kp * e * u_wanted > 0.0
        xn[2] = x[2] + (0.0 if frozen else ki * e)  # forward-Euler integral of eq. 7.2
        xn[3] = e
        xn[4] = d
        # fig. 7.11: nominal plant driven by the applied force
        xn[5] = x[5] + ts * x[6] + b1n * u
        xn[6] = x[6] + b2n * u
        if use_dob:
            # extended-state observer = Q-filter DOB (see DisturbanceObserver)
            innov = y_hat - x[7]
            xn[7] = x[7] + ts * x[8] + b1n * (u + x[9]) + dob[1] * innov
            xn[8] = x[8] + b2n * (u + x[9]) + dob[2] * innov
            xn[9] = x[9] + dob[3] * innov
        force = u + d_in[n]
        xn[0] = x[0] + ts * x[1] + b1 * force  # exact ZOH of 1 / (m s^2)
        xn[1] = x[1] + b2 * force
        if not abs(y) <= y_limit:  # also catches NaN
            return out, x, n, 1
        if not np.isfinite(u):
            return out, x, n, 2
        if not (np.isfinite(s) and np.isfinite(y_hat) and np.isfinite(s_hat)
                and np.isfinite(e)):
            return out, x, n, 3
        out[0, n] = y
        out[1, n] = s
        out[2, n] = y_hat
        out[3, n] = s_hat
        out[4, n] = x[5]
        out[5, n] = e
        out[6, n] = u
        out[7, n] = x[9] if use_dob else 0.0
        x, xn = xn, x
    return out, x, n_steps, 0
