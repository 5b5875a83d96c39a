"""Compiled hot loops of the circuit-type models of sec. 2.1.3-2.1.5.

``chua.py``, ``bobbio.py`` and ``ladder.py`` hold the readable references, the parameter
checks and the documentation; here all arrays are float64 and already validated. Each loop is
O(model size) per sample.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# --- Chua-Stromsmoe, dy/dt = g(u - f(y)) (eq. 2.3) -------------------------------------------


@njit(cache=True, inline="always")
def chua_restoring(y, k0, k_inf, y_s):
    """Restoring function f: odd, slope k0 at 0 and k_inf far out."""
    return k_inf * y + (k0 - k_inf) * y_s * np.tanh(y / y_s)


@njit(cache=True)
def chua_restoring_inverse(u, k0, k_inf, y_s):
    """f_k^-1(u) for every element by bisection; |f(y) - k_inf y| <= |k0 - k_inf| y_s."""
    y = np.empty(k0.size)
    for k in range(k0.size):
        spread = abs(k0[k] - k_inf[k]) * y_s[k]
        lo, hi = (u - spread) / k_inf[k], (u + spread) / k_inf[k]
        while hi - lo > 1e-16 * (1.0 + abs(lo) + abs(hi)):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            if chua_restoring(mid, k0[k], k_inf[k], y_s[k]) >= u:
                hi = mid
            else:
                lo = mid
        y[k] = 0.5 * (lo + hi)
    return y


@njit(cache=True)
def chua_rest_input(y0, k0, k_inf, y_s):
    """The common input u whose rest states sum to y0: sum_k f_k^-1(u) = y0 (increasing)."""
    span = (abs(y0) + 1.0) * np.max(np.maximum(k0, k_inf)) + np.max(np.abs(k0 - k_inf) * y_s)
    lo, hi = -span * k0.size, span * k0.size
    while hi - lo > 1e-16 * (1.0 + abs(lo) + abs(hi)):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if np.sum(chua_restoring_inverse(mid, k0, k_inf, y_s)) >= y0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


@njit(cache=True, inline="always")
def chua_dissipation(v, g, v_g, band, knee, cap):
    """Limited dissipation function g: dead band, sinh, straight line of slope cap."""
    a = abs(v)
    if a <= band:
        return 0.0
    s = 1.0 if v > 0 else -1.0
    if a <= knee:
        return s * g * v_g * np.sinh((a - band) / v_g)
    return s * (g * v_g * np.sinh((knee - band) / v_g) + cap * (a - knee))


@njit(cache=True, inline="always")
def _chua_dissipation_inverse(r, g, v_g, band, knee, cap, upper):
    """Smallest (``upper`` False) or largest v with g(v) = r; differ only for r = 0."""
    if r == 0.0:
        return band if upper else -band
    s = 1.0 if r > 0 else -1.0
    a = abs(r)
    g_knee = g * v_g * np.sinh((knee - band) / v_g)
    if a <= g_knee:
        return s * (band + v_g * np.arcsinh(a / (g * v_g)))
    return s * (knee + (a - g_knee) / cap)


@njit(cache=True)
def chua_simulate(u, x0, k0, k_inf, y_s, g, v_g, band, knee, cap, dt):
    x = x0.copy()
    y = np.empty(u.size)
    for n in range(u.size):
        acc = 0.0
        for k in range(x.size):
            v = u[n] - chua_restoring(x[k], k0[k], k_inf[k], y_s[k])
            x[k] += dt * chua_dissipation(v, g[k], v_g[k], band[k], knee[k], cap[k])
            acc += x[k]
        y[n] = acc
    return y, x


@njit(cache=True)
def _chua_rate(u, fx, g, v_g, band, knee, cap):
    acc = 0.0
    for k in range(fx.size):
        acc += chua_dissipation(u - fx[k], g[k], v_g[k], band[k], knee[k], cap[k])
    return acc


@njit(cache=True)
def chua_solve_input(r, fx, g, v_g, band, knee, cap):
    """Input u with sum_k g_k(u - f_k(x_k)) = r, by bisection (the sum is non-decreasing in u).

    Where the sum is flat (r = 0 with all elements in their dead bands) the middle of the flat
    interval is returned. Bracket: at min_k(f_k + g_k^-1(r/N)) every term is <= r/N, at the max
    every term is >= r/N.
    """
    n_el = fx.size
    lo, hi = np.inf, -np.inf
    for k in range(n_el):
        lo = min(lo, fx[k] + _chua_dissipation_inverse(r / n_el, g[k], v_g[k], band[k],
                                                       knee[k], cap[k], False))
        hi = max(hi, fx[k] + _chua_dissipation_inverse(r / n_el, g[k], v_g[k], band[k],
                                                       knee[k], cap[k], True))
    ends = np.empty(2)
    for side in range(2):  # 0: first u with rate >= r; 1: last u with rate <= r
        a, b = lo, hi
        while b - a > 1e-14 * (1.0 + abs(a) + abs(b)):
            m = 0.5 * (a + b)
            h = _chua_rate(m, fx, g, v_g, band, knee, cap)
            if h > r or (side == 0 and h == r):
                b = m
            else:
                a = m
        ends[side] = b if side == 0 else a
    return 0.5 * (ends[0] + ends[1])


@njit(cache=True)
def chua_invert(y, x0, k0, k_inf, y_s, g, v_g, band, knee, cap, dt):
    """Exact inverse of ``chua_simulate``; returns the first diverging sample or -1."""
    x = x0.copy()
    fx = np.empty(x.size)
    u_hat = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    for n in range(y.size):
        for k in range(x.size):
            fx[k] = chua_restoring(x[k], k0[k], k_inf[k], y_s[k])
        r = (y[n] - np.sum(x)) / dt
        e = chua_solve_input(r, fx, g, v_g, band, knee, cap)
        if not abs(e) < bound:
            return u_hat, x, n
        u_hat[n] = e
        for k in range(x.size):
            x[k] += dt * chua_dissipation(e - fx[k], g[k], v_g[k], band[k], knee[k], cap[k])
    return u_hat, x, -1


# --- Bobbio-Marrucci spring/piston chain (eq. 2.5) ------------------------------------------


@njit(cache=True)
def bobbio_forces(u, x0, a):
    """Spring forces F_2..F_N per sample: projection onto |F_k - F_k+1| <= a_k, k = 1..N-1."""
    x = x0.copy()
    forces = np.empty((u.size, x.size))
    for n in range(u.size):
        prev = u[n]
        for k in range(x.size):
            if x[k] < prev - a[k]:
                x[k] = prev - a[k]
            elif x[k] > prev + a[k]:
                x[k] = prev + a[k]
            prev = x[k]
            forces[n, k] = x[k]
    return forces, x


@njit(cache=True)
def bobbio_invert(y, x0, c, a, b):
    """Applied force from the deformation: walk the piecewise-linear, non-decreasing Y(F).

    Returns the first sample where no force gives ``y`` (all compliances zero), or -1.
    """
    x = x0.copy()
    m = x.size
    u_hat = np.empty(y.size)
    for n in range(y.size):
        target = y[n] - b
        stored = 0.0
        for k in range(m):
            stored += c[k + 1] * x[k]
        # while piston 1 sticks, F moves inside [x_1 - a_1, x_1 + a_1] and only spring 1 yields
        centre = x[0] if m > 0 else 0.0
        half = a[0] if m > 0 else np.inf
        at_top = c[0] * (centre + half) + stored if m > 0 else np.inf
        at_bottom = c[0] * (centre - half) + stored if m > 0 else -np.inf
        if m == 0 and c[0] == 0.0:
            return u_hat, x, n
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
                nxt = x[k + 1] + s * (reach + a[k + 1])
                if s * (level + slope * (nxt - f)) >= s * target:
                    break
                level += slope * (nxt - f)
                f = nxt
            if slope == 0.0:
                return u_hat, x, n
            f += (target - level) / slope
        u_hat[n] = f
        prev = f
        for k in range(m):
            x[k] = min(max(x[k], prev - a[k]), prev + a[k])
            prev = x[k]
    return u_hat, x, -1


# --- PWL ladder circuit (sec. 2.1.5) ---------------------------------------------------------


@njit(cache=True, inline="always")
def _dead_zone_current(v, band, g):
    if v > band:
        return g * (v - band)
    if v < -band:
        return g * (v + band)
    return 0.0


@njit(cache=True, inline="always")
def _ladder_euler(e, x, band, g, dt, cur):
    """One forward-Euler step of the capacitor voltages, all currents from the old state."""
    n_cells = x.size
    upstream = e
    for k in range(n_cells):
        cur[k] = _dead_zone_current(upstream - x[k], band[k], g[k])
        upstream = x[k]
    for k in range(n_cells):
        out = cur[k + 1] if k + 1 < n_cells else 0.0
        x[k] += dt * (cur[k] - out)


@njit(cache=True)
def ladder_states(u, x0, band, g, dt):
    """Capacitor voltages at each sample, before that sample's update (output first)."""
    x = x0.copy()
    cur = np.empty(x.size)
    states = np.empty((u.size, x.size))
    for n in range(u.size):
        states[n] = x
        _ladder_euler(u[n], x, band, g, dt, cur)
    return states, x


@njit(cache=True)
def ladder_invert(y, x0, band, g, w, v_b, dt):
    """Analytical inverse, output equation first, then the state update (as eq. 5.13-5.14)."""
    x = x0.copy()
    cur = np.empty(x.size)
    u_hat = np.empty(y.size)
    bound = 1e6 * (1.0 + np.max(np.abs(y)))
    for n in range(y.size):
        acc = y[n] + v_b
        for k in range(x.size):
            acc -= w[k + 1] * x[k]
        e = acc / w[0]
        if not abs(e) < bound:
            return u_hat, x, n
        u_hat[n] = e
        _ladder_euler(e, x, band, g, dt, cur)
    return u_hat, x, -1
