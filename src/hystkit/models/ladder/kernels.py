"""Compiled hot loops of the PWL ladder circuit; ``model.py`` holds the readable reference.

All arrays are float64 and already validated; ``g`` is the effective (Euler-limited)
conductance of each resistor. The state ``x`` is the capacitor voltages ``U_1 .. U_N``. Each loop
is O(N) per sample.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _dead_zone_current(v, band, g):
    if v > band:
        return g * (v - band)
    if v < -band:
        return g * (v + band)
    return 0.0


@njit(cache=True, inline="always")
def euler(e, x, xn, off, band, g, dt):
    """One forward-Euler step of the capacitor voltages, all currents from the old state:
    ``xn[off + k]`` from ``x[off + k]`` (may be the same array)."""
    n_cells = band.size
    i_in = _dead_zone_current(e - x[off], band[0], g[0])
    for k in range(n_cells):
        i_out = 0.0
        if k + 1 < n_cells:
            i_out = _dead_zone_current(x[off + k] - x[off + k + 1], band[k + 1], g[k + 1])
        xn[off + k] = x[off + k] + dt * (i_in - i_out)
        i_in = i_out


@njit(cache=True, inline="always")
def output(e, x, off, w, v_b):
    """``y = w_0 e + sum_k w_k U_k - V_b`` from the present voltages."""
    acc = w[0] * e - v_b
    for k in range(w.size - 1):
        acc += w[k + 1] * x[off + k]
    return acc


@njit(cache=True, inline="always")
def solve_input(y, x, off, w, v_b):
    """The source voltage whose output is ``y``: ``(y + V_b - sum_k w_k U_k) / w_0``."""
    acc = y + v_b
    for k in range(w.size - 1):
        acc -= w[k + 1] * x[off + k]
    return acc / w[0]


@njit(cache=True)
def simulate(u, x0, band, g, w, v_b, dt):
    """Output from the present voltages (:func:`output`), then the Euler step, per sample: the
    forward block's arithmetic, so a stream or a loop of blocks gives these bits (a matrix
    product of :func:`states` would sum in BLAS's order, which depends on the machine)."""
    x = x0.copy()
    y = np.empty(u.size)
    for n in range(u.size):
        y[n] = output(u[n], x, 0, w, v_b)
        euler(u[n], x, x, 0, band, g, dt)
    return y, x


@njit(cache=True)
def states(u, x0, band, g, dt):
    """Capacitor voltages at each sample, before that sample's update (output first)."""
    x = x0.copy()
    out = np.empty((u.size, x.size))
    for n in range(u.size):
        out[n] = x
        euler(u[n], x, x, 0, band, g, dt)
    return out, x


@njit(cache=True)
def invert(y, x0, band, g, w, v_b, dt):
    """Analytical inverse, output equation first, then the state update (as eq. 5.13-5.14)."""
    x = x0.copy()
    u_hat = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    for n in range(y.size):
        e = solve_input(y[n], x, 0, w, v_b)
        if not abs(e) < bound:
            return u_hat, x, n
        u_hat[n] = e
        euler(e, x, x, 0, band, g, dt)
    return u_hat, x, -1


# Loop blocks (protocol in ``hystkit.models._protocol``): body = [N, V_b, dt, band (N),
# effective conductance (N), w (N + 1)], as ``LadderFamily.block`` packs it.

@njit(cache=True, inline="always")
def _unpack(body):
    n = int(body[0])
    return body[3:3 + n], body[3 + n:3 + 2 * n], body[3 + 2 * n:4 + 3 * n], body[1], body[2]


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """Output from the present voltages, then the Euler step driven by ``u``."""
    band, g, w, v_b, dt = _unpack(body)
    y = output(u, x, off, w, v_b)
    euler(u, x, xn, off, band, g, dt)
    return y


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """``e = (y + V_b - sum w_k U_k) / w_0``, then the Euler step driven by ``e``."""
    band, g, w, v_b, dt = _unpack(body)
    e = solve_input(y, x, off, w, v_b)
    euler(e, x, xn, off, band, g, dt)
    return e
