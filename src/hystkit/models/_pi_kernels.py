"""Compiled hot loops of the Kuhnen / modified Prandtl-Ishlinskii model; ``pi.py`` holds the
readable reference, the checks and the equations.

All arrays are float64 and already validated by the caller. Per sample the cost is
O(plays + dead zones + creep operators), independent of any grid.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _superposition(v, d, w):
    """One-sided dead-zone operators ``S_d`` weighted and summed (eq. 2.12)."""
    acc = 0.0
    for j in range(d.size):
        if d[j] > 0.0:
            acc += w[j] * max(v - d[j], 0.0)
        elif d[j] < 0.0:
            acc += w[j] * min(v - d[j], 0.0)
        else:
            acc += w[j] * v
    return acc


@njit(cache=True)
def simulate(u, p0, z0, r, w_h, d_s, w_s, c, w_k, b):
    """Forward model ``y = S[H[u] + K[u] + b]``; returns ``y``, play and creep states."""
    p = p0.copy()
    z = z0.copy()
    y = np.empty(u.size)
    for n in range(u.size):
        x = u[n]
        v = b
        for i in range(r.size):
            p[i] = max(x - r[i], min(x + r[i], p[i]))  # eq. 2.11
            v += w_h[i] * p[i]
        for j in range(c.size):
            z[j] += c[j] * (x - z[j])  # exact for the input held over the last sample
            v += w_k[j] * z[j]
        y[n] = _superposition(v, d_s, w_s)
    return y, p, z


@njit(cache=True)
def invert(y, q0, z0, r_inv, w_inv, d_inv, ws_inv, c, w_k, b):
    """Inverse model (eq. 2.19 with creep): ``u = H~'[S'[y] - b - creep memory]``.

    ``r_inv``/``w_inv`` are the inverse play thresholds/weights of the instantaneous operator
    ``H + diag(c) K`` and ``q0`` its inverse play states; ``z0`` the creep states. Returns the
    input estimate, the final states and the index of the first sample that left the finite
    range (or -1).
    """
    q = q0.copy()
    z = z0.copy()
    u = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    for n in range(y.size):
        v = _superposition(y[n], d_inv, ws_inv) - b
        for j in range(c.size):
            v -= w_k[j] * (1.0 - c[j]) * z[j]  # the part of the creep the past fixed
        x = 0.0
        for i in range(r_inv.size):
            q[i] = max(v - r_inv[i], min(v + r_inv[i], q[i]))
            x += w_inv[i] * q[i]
        if not abs(x) < bound:
            return u, q, z, n
        u[n] = x
        for j in range(c.size):
            z[j] += c[j] * (x - z[j])
    return u, q, z, -1


@njit(cache=True)
def regressors(u, p0, z0, r, c):
    """Play outputs (n, n_play) and creep states (n, n_creep) over ``u``: the columns the
    output of ``H + K`` is linear in (identification)."""
    p = p0.copy()
    z = z0.copy()
    plays = np.empty((u.size, r.size))
    creep = np.empty((u.size, c.size))
    for n in range(u.size):
        x = u[n]
        for i in range(r.size):
            p[i] = max(x - r[i], min(x + r[i], p[i]))
            plays[n, i] = p[i]
        for j in range(c.size):
            z[j] += c[j] * (x - z[j])
            creep[n, j] = z[j]
    return plays, creep
