"""Compiled hot loops of the Kuhnen / modified Prandtl-Ishlinskii model; ``model.py`` holds the
readable reference, the checks and the equations.

All arrays are float64 and already validated by the caller. Per sample the cost is
O(plays + dead zones + creep operators), independent of any grid. The per-sample pieces
(:func:`_move`, :func:`_output`, :func:`_inverse_target`) are shared by the run kernels and the
loop blocks.
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


@njit(cache=True, inline="always")
def _move(x, p, z, r, c):
    """Plays (eq. 2.11) and creep states (exact for the input held over the last sample)
    moved by the input ``x``, in place."""
    for i in range(r.size):
        p[i] = max(x - r[i], min(x + r[i], p[i]))
    for j in range(c.size):
        z[j] += c[j] * (x - z[j])


@njit(cache=True, inline="always")
def _output(p, z, w_h, w_k, b):
    """``H[x] + K[x] + b`` from the moved states (the argument of ``S``)."""
    v = b
    for i in range(p.size):
        v += w_h[i] * p[i]
    for j in range(z.size):
        v += w_k[j] * z[j]
    return v


@njit(cache=True, inline="always")
def _inverse_target(y, z, d_inv, ws_inv, c, w_k, b):
    """``S^-1[y] - b`` minus the part of the creep the past fixed: what ``H~`` must give."""
    v = _superposition(y, d_inv, ws_inv) - b
    for j in range(c.size):
        v -= w_k[j] * (1.0 - c[j]) * z[j]
    return v


@njit(cache=True)
def simulate(u, p0, z0, r, w_h, d_s, w_s, c, w_k, b):
    """Forward model ``y = S[H[u] + K[u] + b]``; returns ``y``, play and creep states."""
    p = p0.copy()
    z = z0.copy()
    y = np.empty(u.size)
    for n in range(u.size):
        _move(u[n], p, z, r, c)
        y[n] = _superposition(_output(p, z, w_h, w_k, b), d_s, w_s)
    return y, p, z


@njit(cache=True, inline="always")
def _inverse_estimate(y, p, z, r_inv, w_inv, w, d_inv, sws_inv, c, sw_k, sb):
    """The input estimate of one inverse sample from the present forward state ``p``, ``z``
    (read only): ``sign * H~`` inverted by inverse plays whose states ``q_i = W_i p_i +
    sum_{j>i} w_j p_j`` are formed from ``p`` (tail sums, no scratch), ``u = sum w'_i
    play(v, q_i)`` with ``v`` the target of :func:`_inverse_target`."""
    n = p.size
    big_w = 0.0
    for j in range(n):
        big_w += w[j]
    v = _inverse_target(y, z, d_inv, sws_inv, c, sw_k, sb)
    u_hat = 0.0
    tail = 0.0
    for j in range(n - 1, -1, -1):  # W_j = W_n-1 - (w_j+1 + .. + w_n-1)
        q = big_w * p[j] + tail
        u_hat += w_inv[j] * max(v - r_inv[j], min(v + r_inv[j], q))
        tail += w[j] * p[j]
        big_w -= w[j]
    return u_hat


@njit(cache=True)
def invert(y, p0, z0, r, r_inv, w_inv, w, d_inv, sws_inv, c, sw_k, sb):
    """Inverse model (eq. 2.19 with creep): ``u = H~'[S'[y] - b - creep memory]``.

    Carries the forward state (plays ``p0``, creep ``z0``): each sample forms the inverse
    plays of ``sign * H~`` (thresholds ``r_inv``, weights ``w_inv``, ``w = sign * w~``) from
    the present plays (:func:`_inverse_estimate`), then moves the forward state by the
    estimate, as :func:`block_inverse` does, so a loop of blocks (a stream) gives these bits.
    ``sws_inv``, ``sw_k``, ``sb``: ``S^-1``'s weights, the creep weights and ``b`` times the
    sign. Returns the input estimate, the final plays and creep states and the index of the
    first sample that left the finite range (or -1; the states are those before it).
    """
    p = p0.copy()
    z = z0.copy()
    u = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    for n in range(y.size):
        x = _inverse_estimate(y[n], p, z, r_inv, w_inv, w, d_inv, sws_inv, c, sw_k, sb)
        if not abs(x) < bound:
            return u, p, z, n
        u[n] = x
        _move(x, p, z, r, c)
    return u, p, z, -1


@njit(cache=True)
def regressors(u, p0, z0, r, c):
    """Play outputs (n, n_play) and creep states (n, n_creep) over ``u``: the columns the
    output of ``H + K`` is linear in (identification)."""
    p = p0.copy()
    z = z0.copy()
    plays = np.empty((u.size, r.size))
    creep = np.empty((u.size, c.size))
    for n in range(u.size):
        _move(u[n], p, z, r, c)
        plays[n, :] = p
        creep[n, :] = z
    return plays, creep


# Loop blocks (protocol in ``hystkit.models._protocol``). State slice: the forward state
# ``[p_0 .. p_{n-1}, z_1 .. z_m]`` for both directions (as ``model.invert``).
# Forward body:  [n, m, k, b, r (n), w_h (n), c (m), w_k (m), d_s (k), w_s (k)].
# Inverse body:  [n, m, k, sign b, r (n), w_h (n), c (m), sign w_k (m), d_inv (k),
#                 sign ws_inv (k), r_inv (n), w_inv (n), sign w~ (n)]  (``model.inverse_parts``).

@njit(cache=True, inline="always")
def _block_parts(body):
    n, m, k = int(body[0]), int(body[1]), int(body[2])
    i = 4
    r, w_h = body[i:i + n], body[i + n:i + 2 * n]
    i += 2 * n
    c, w_k = body[i:i + m], body[i + m:i + 2 * m]
    i += 2 * m
    d, w_d = body[i:i + k], body[i + k:i + 2 * k]
    return n, m, body[3], r, w_h, c, w_k, d, w_d, i + 2 * k


@njit(cache=True, inline="always")
def _block_states(x, xn, off, n, m):
    """The next-state slices of ``xn``, loaded with the present state of ``x``."""
    p = xn[off:off + n]
    z = xn[off + n:off + n + m]
    for i in range(n + m):
        xn[off + i] = x[off + i]
    return p, z


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """States moved by ``u``, then ``y = S[H + K + b]`` (eq. 2.12-2.15)."""
    n, m, b, r, w_h, c, w_k, d_s, w_s, _ = _block_parts(body)
    p, z = _block_states(x, xn, off, n, m)
    _move(u, p, z, r, c)
    return _superposition(_output(p, z, w_h, w_k, b), d_s, w_s)


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """One sample of the inverse on the forward state (``model.invert_step``): the estimate
    of :func:`_inverse_estimate` from the present state, which it then moves as
    :func:`block_forward` would (the arithmetic of :func:`invert`)."""
    n, m, sb, r, _, c, sw_k, d_inv, sws_inv, i = _block_parts(body)
    r_inv, w_inv, w = body[i:i + n], body[i + n:i + 2 * n], body[i + 2 * n:i + 3 * n]
    u_hat = _inverse_estimate(y, x[off:off + n], x[off + n:off + n + m], r_inv, w_inv, w,
                              d_inv, sws_inv, c, sw_k, sb)
    p, z = _block_states(x, xn, off, n, m)
    _move(u_hat, p, z, r, c)
    return u_hat
