"""Compiled hot loops of the Bobbio-Marrucci chain; ``model.py`` holds the readable reference.

All arrays are float64 and already validated. The state ``x`` is the spring forces
``F_2 .. F_N`` (``F_1`` is the input); ``a`` the piston thresholds, ``c`` the compliances,
``b`` the output offset. Each loop is O(N) per sample.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def project(x, xn, off, u, a):
    """Apply force ``u``: ``F_k+1 <- clip(F_k+1, F_k - a_k, F_k + a_k)`` from the loaded end
    inwards (eq. 2.5), ``xn[off + k]`` from ``x[off + k]`` (may be the same array)."""
    prev = u
    for k in range(a.size):
        xn[off + k] = min(max(x[off + k], prev - a[k]), prev + a[k])
        prev = xn[off + k]


@njit(cache=True)
def forces(u, x0, a):
    """Spring forces F_2..F_N after each sample, and the final state."""
    x = x0.copy()
    out = np.empty((u.size, x.size))
    for n in range(u.size):
        project(x, x, 0, u[n], a)
        out[n] = x
    return out, x


@njit(cache=True)
def simulate(u, x0, a, c, b):
    """Forward model: forces projected by each sample, then ``y = c_1 u + sum_k c_k F_k + b``
    (as :func:`block_forward`); returns ``y`` and the final state. One pass: :func:`forces`'
    (n, N - 1) array and a matrix product after it cost 1.2-1.4x this at 100k samples."""
    x = x0.copy()
    y = np.empty(u.size)
    for n in range(u.size):
        project(x, x, 0, u[n], a)
        acc = c[0] * u[n]
        for k in range(a.size):
            acc += c[k + 1] * x[k]
        y[n] = acc + b
    return y, x


@njit(cache=True)
def invert_sample(x, xn, off, y, c, a, b):
    """The applied force that gives deformation ``y``: walk the piecewise-linear,
    non-decreasing ``Y(F)``; then project the state with it into ``xn``.

    Returns NaN (and leaves ``xn`` alone) when no force gives ``y`` (all compliances zero).
    """
    m = a.size
    target = y - b
    stored = 0.0
    for k in range(m):
        stored += c[k + 1] * x[off + k]
    if m == 0:
        if c[0] == 0.0:
            return np.nan
        return (target - stored) / c[0]
    # while piston 1 sticks, F moves inside [F_2 - a_1, F_2 + a_1] and only spring 1 yields
    centre = x[off]
    half = a[0]
    at_top = c[0] * (centre + half) + stored
    at_bottom = c[0] * (centre - half) + stored
    if at_bottom <= target <= at_top:
        f = centre if c[0] == 0.0 else (target - stored) / c[0]
    else:
        s = 1.0 if target > at_top else -1.0
        f = centre + s * half
        level = at_top if s > 0 else at_bottom
        slope = c[0]
        reach = 0.0
        for k in range(m):
            reach += a[k]
            slope += c[k + 1]
            if k + 1 == m:  # every spring yields: the last segment has no end
                break
            # spring k+3 starts yielding when F passes F_k+3 +- (a_1 + .. + a_k+2)
            nxt = x[off + k + 1] + s * (reach + a[k + 1])
            if s * (level + slope * (nxt - f)) >= s * target:
                break
            level += slope * (nxt - f)
            f = nxt
        if slope == 0.0:
            return np.nan
        f += (target - level) / slope
    project(x, xn, off, f, a)
    return f


@njit(cache=True)
def invert(y, x0, c, a, b):
    """Applied force from the deformation; returns the first sample that no force gives, or -1."""
    x = x0.copy()
    u_hat = np.empty(y.size)
    for n in range(y.size):
        f = invert_sample(x, x, 0, y[n], c, a, b)
        if np.isnan(f):
            return u_hat, x, n
        u_hat[n] = f
    return u_hat, x, -1


# Loop blocks (protocol in ``hystkit.models._protocol``): body = [N, b, c (N), a (N - 1)].

@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """Project the forces with ``u``; ``y = c_1 u + sum_k c_k F_k + b``."""
    n = int(body[0])
    c, a = body[2:2 + n], body[2 + n:1 + 2 * n]
    project(x, xn, off, u, a)
    acc = c[0] * u
    for k in range(n - 1):
        acc += c[k + 1] * xn[off + k]
    return acc + body[1]


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """The force that gives ``y`` (NaN, and a NaN state, where none does)."""
    n = int(body[0])
    f = invert_sample(x, xn, off, y, body[2:2 + n], body[2 + n:1 + 2 * n], body[1])
    if np.isnan(f):
        for k in range(n - 1):
            xn[off + k] = np.nan
    return f
