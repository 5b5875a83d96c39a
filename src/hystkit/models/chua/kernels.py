"""Compiled hot loops of the Chua-Stromsmoe model; ``model.py`` holds the readable reference.

All arrays are float64 and already validated. Each loop is O(elements) per sample. Per element
the dissipation function is limited beyond ``knee`` to a straight line of slope ``cap`` (the
Euler limit, see ``model.py``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# Relative output change (of max(1, |y|, sum |y_k|)) below which the inverse takes the output
# as constant, ``r = 0``: rounding of the state's sum must not pick a dead band's edge.
REST_TOL = 1e-12


@njit(cache=True, inline="always")
def restoring(y, k0, k_inf, y_s):
    """Restoring function f: odd, slope k0 at 0 and k_inf far out."""
    return k_inf * y + (k0 - k_inf) * y_s * np.tanh(y / y_s)


@njit(cache=True)
def restoring_inverse(u, k0, k_inf, y_s):
    """f_k^-1(u) for every element by bisection; |f(y) - k_inf y| <= |k0 - k_inf| y_s."""
    y = np.empty(k0.size)
    for k in range(k0.size):
        spread = abs(k0[k] - k_inf[k]) * y_s[k]
        lo, hi = (u - spread) / k_inf[k], (u + spread) / k_inf[k]
        while hi - lo > 1e-16 * (1.0 + abs(lo) + abs(hi)):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            if restoring(mid, k0[k], k_inf[k], y_s[k]) >= u:
                hi = mid
            else:
                lo = mid
        y[k] = 0.5 * (lo + hi)
    return y


@njit(cache=True)
def rest_input(y0, k0, k_inf, y_s):
    """The common input u whose rest states sum to y0: sum_k f_k^-1(u) = y0 (increasing)."""
    span = (abs(y0) + 1.0) * np.max(np.maximum(k0, k_inf)) + np.max(np.abs(k0 - k_inf) * y_s)
    lo, hi = -span * k0.size, span * k0.size
    while hi - lo > 1e-16 * (1.0 + abs(lo) + abs(hi)):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if np.sum(restoring_inverse(mid, k0, k_inf, y_s)) >= y0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


@njit(cache=True, inline="always")
def dissipation(v, g, v_g, band, knee, cap):
    """Limited dissipation function g: dead band, sinh, straight line of slope cap."""
    g_knee = g * v_g * np.sinh((knee - band) / v_g) if abs(v) > knee else 0.0
    return _dissipation(v, g, v_g, band, knee, cap, g_knee)


@njit(cache=True, inline="always")
def _dissipation(v, g, v_g, band, knee, cap, g_knee):
    """:func:`dissipation` with its value at the knee, ``g_knee``, given (used beyond it)."""
    a = abs(v)
    if a <= band:
        return 0.0
    s = 1.0 if v > 0 else -1.0
    if a <= knee:
        return s * g * v_g * np.sinh((a - band) / v_g)
    return s * (g_knee + cap * (a - knee))


@njit(cache=True, inline="always")
def _dissipation_inverse(r, g, v_g, band, knee, cap, upper):
    """Smallest (``upper`` False) or largest v with g(v) = r; differ only for r = 0."""
    if r == 0.0:
        return band if upper else -band
    s = 1.0 if r > 0 else -1.0
    a = abs(r)
    g_knee = g * v_g * np.sinh((knee - band) / v_g)
    if a <= g_knee:
        return s * (band + v_g * np.arcsinh(a / (g * v_g)))
    return s * (knee + (a - g_knee) / cap)


@njit(cache=True, inline="always")
def advance(x, xn, off, u, k0, k_inf, y_s, g, v_g, band, knee, cap, dt):
    """One Euler step of every element, ``xn[off + k]`` from ``x[off + k]`` (may be the same
    array); returns the output, the sum of the new element states."""
    acc = 0.0
    for k in range(k0.size):
        v = u - restoring(x[off + k], k0[k], k_inf[k], y_s[k])
        xn[off + k] = x[off + k] + dt * dissipation(v, g[k], v_g[k], band[k], knee[k], cap[k])
        acc += xn[off + k]
    return acc


@njit(cache=True)
def simulate(u, x0, k0, k_inf, y_s, g, v_g, band, knee, cap, dt):
    x = x0.copy()
    y = np.empty(u.size)
    # g at each knee once, not a sinh per sample beyond it (fits put the knee at the dead
    # band's edge, so every sample is beyond it: 23.1 -> 21.0 ns/sample, same bits); the rest
    # is advance's step
    g_knee = g * v_g * np.sinh((knee - band) / v_g)
    for n in range(u.size):
        acc = 0.0
        for k in range(k0.size):
            v = u[n] - restoring(x[k], k0[k], k_inf[k], y_s[k])
            x[k] = x[k] + dt * _dissipation(v, g[k], v_g[k], band[k], knee[k], cap[k], g_knee[k])
            acc += x[k]
        y[n] = acc
    return y, x


@njit(cache=True)
def _rate(u, fx, g, v_g, band, knee, cap):
    acc = 0.0
    for k in range(fx.size):
        acc += dissipation(u - fx[k], g[k], v_g[k], band[k], knee[k], cap[k])
    return acc


@njit(cache=True)
def solve_input(r, fx, g, v_g, band, knee, cap):
    """Input u with sum_k g_k(u - f_k(x_k)) = r, by bisection (the sum is non-decreasing in u).

    Where the sum is flat (r = 0 with all elements in their dead bands) the middle of the flat
    interval is returned. Bracket: at min_k(f_k + g_k^-1(r/N)) every term is <= r/N, at the max
    every term is >= r/N.
    """
    n_el = fx.size
    lo, hi = np.inf, -np.inf
    for k in range(n_el):
        lo = min(lo, fx[k] + _dissipation_inverse(r / n_el, g[k], v_g[k], band[k],
                                                       knee[k], cap[k], False))
        hi = max(hi, fx[k] + _dissipation_inverse(r / n_el, g[k], v_g[k], band[k],
                                                       knee[k], cap[k], True))
    ends = np.empty(2)
    for side in range(2):  # 0: first u with rate >= r; 1: last u with rate <= r
        a, b = lo, hi
        while b - a > 1e-14 * (1.0 + abs(a) + abs(b)):
            m = 0.5 * (a + b)
            h = _rate(m, fx, g, v_g, band, knee, cap)
            if h > r or (side == 0 and h == r):
                b = m
            else:
                a = m
        ends[side] = b if side == 0 else a
    return 0.5 * (ends[0] + ends[1])


@njit(cache=True)
def invert_sample(x, xn, off, y, k0, k_inf, y_s, g, v_g, band, knee, cap, dt):
    """The input that makes :func:`advance` return ``y``; writes the state it leaves to ``xn``."""
    n_el = k0.size
    fx = np.empty(n_el)
    total = size = 0.0
    for k in range(n_el):
        fx[k] = restoring(x[off + k], k0[k], k_inf[k], y_s[k])
        total += x[off + k]
        size += abs(x[off + k])
    if abs(y - total) <= REST_TOL * max(1.0, abs(y), size):
        y = total  # the present output to rounding: no element moves (the middle of the band)
    e = solve_input((y - total) / dt, fx, g, v_g, band, knee, cap)
    for k in range(n_el):
        xn[off + k] = x[off + k] + dt * dissipation(e - fx[k], g[k], v_g[k], band[k], knee[k],
                                                    cap[k])
    return e


@njit(cache=True)
def invert(y, x0, k0, k_inf, y_s, g, v_g, band, knee, cap, dt):
    """Exact inverse of :func:`simulate`; returns the first diverging sample or -1."""
    x = x0.copy()
    u_hat = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    for n in range(y.size):
        x_before = x.copy()
        e = invert_sample(x_before, x, 0, y[n], k0, k_inf, y_s, g, v_g, band, knee, cap, dt)
        if not abs(e) < bound:
            return u_hat, x_before, n
        u_hat[n] = e
    return u_hat, x, -1


# Loop blocks (protocol in ``hystkit.models._protocol``): body = [N, dt, k0 (N), k_inf (N),
# y_s (N), g (N), v_g (N), delta (N), knee (N), cap (N)], as ``ChuaFamily.block`` packs it.

@njit(cache=True, inline="always")
def _unpack(body):
    n = int(body[0])
    p = body[2:]
    return (p[:n], p[n:2 * n], p[2 * n:3 * n], p[3 * n:4 * n], p[4 * n:5 * n],
            p[5 * n:6 * n], p[6 * n:7 * n], p[7 * n:8 * n], body[1])


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """Euler step of every element driven by ``u``; the output is the sum of the new states."""
    k0, k_inf, y_s, g, v_g, band, knee, cap, dt = _unpack(body)
    return advance(x, xn, off, u, k0, k_inf, y_s, g, v_g, band, knee, cap, dt)


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """The input whose Euler step gives ``y`` (bisection), and the state it leaves."""
    k0, k_inf, y_s, g, v_g, band, knee, cap, dt = _unpack(body)
    return invert_sample(x, xn, off, y, k0, k_inf, y_s, g, v_g, band, knee, cap, dt)
