"""Compiled hot loops of the mPL model; ``mpl.py`` holds the readable reference and the checks.

All arrays are float64 and already validated by the caller. ``knee`` is the per-cell voltage
beyond which the resistor is linear with slope ``cap`` (eq. 5.29, see ``mpl.py``).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _current(v, i_s, v_t, knee, cap):
    """Limited sinh resistor current and its slope at ``v``."""
    if abs(v) <= knee:
        return 2.0 * i_s * np.sinh(v / v_t), 2.0 * i_s / v_t * np.cosh(v / v_t)
    s = 1.0 if v > 0 else -1.0
    return s * 2.0 * i_s * np.sinh(knee / v_t) + cap * (v - s * knee), cap


@njit(cache=True)
def simulate(u, x0, i_s, v_t, w, v_b, knee, cap, dt):
    n_cells = x0.size
    x = x0.copy()
    y = np.empty(u.size)
    for n in range(u.size):
        acc = w[0] * u[n] - v_b
        for k in range(n_cells):
            acc += w[k + 1] * x[k]
        y[n] = acc
        for k in range(n_cells):
            f, _ = _current(u[n] - x[k], i_s[k], v_t[k], knee[k], cap)
            x[k] += f * dt
    return y, x


@njit(cache=True)
def invert(y, x0, i_s, v_t, w, v_b, knee, cap, dt):
    """Inverse model (eq. 5.13-5.14): output first, then state update (fig. 5.12).

    Returns the index of the first sample that left the finite range, or -1.
    """
    n_cells = x0.size
    x = x0.copy()
    u_hat = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    for n in range(y.size):
        acc = y[n] + v_b
        for k in range(n_cells):
            acc -= w[k + 1] * x[k]
        e = acc / w[0]
        if not abs(e) < bound:
            return u_hat, x, n
        u_hat[n] = e
        for k in range(n_cells):
            f, _ = _current(e - x[k], i_s[k], v_t[k], knee[k], cap)
            x[k] += f * dt
    return u_hat, x, -1


@njit(cache=True)
def simulate_with_jacobian(u, x0, i_s, v_t, w, v_b, knee, cap, dt):
    """Forward model output and its exact Jacobian by forward sensitivities.

    Columns follow ``MplParams.to_vector``: per cell ``log G_k`` and ``log V_Tk``
    (``G = 2 I_S / V_T``), then ``w_0 .. w_N`` and ``V_b``. Inside the knee
    ``df/dlog G = f`` and ``df/dlog V_T = f - v f'(v)``; on the straight continuation the knee's
    own dependence cancels because ``f'(knee) = cap``, leaving the same terms at the knee.
    """
    n_cells = x0.size
    x = x0.copy()
    sens = np.zeros((n_cells, 2))
    y = np.empty(u.size)
    jac = np.empty((u.size, 3 * n_cells + 2))
    for n in range(u.size):
        acc = w[0] * u[n] - v_b
        for k in range(n_cells):
            acc += w[k + 1] * x[k]
            jac[n, 2 * k] = w[k + 1] * sens[k, 0]
            jac[n, 2 * k + 1] = w[k + 1] * sens[k, 1]
            jac[n, 2 * n_cells + 1 + k] = x[k]
        y[n] = acc
        jac[n, 2 * n_cells] = u[n]
        jac[n, 3 * n_cells + 1] = -1.0
        for k in range(n_cells):
            v = u[n] - x[k]
            f, slope = _current(v, i_s[k], v_t[k], knee[k], cap)
            if abs(v) <= knee[k]:
                d_log_g = f
                d_log_vt = f - v * slope
            else:
                s = 1.0 if v > 0 else -1.0
                f_knee = 2.0 * i_s[k] * np.sinh(knee[k] / v_t[k])
                d_log_g = s * f_knee
                d_log_vt = s * (f_knee - knee[k] * cap)
            sens[k, 0] += (d_log_g - slope * sens[k, 0]) * dt
            sens[k, 1] += (d_log_vt - slope * sens[k, 1]) * dt
            x[k] += f * dt
    return y, jac
