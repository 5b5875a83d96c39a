"""One limited sinh cell of the mPL model, compiled: its current (:func:`current`), one Euler
increment with one ``exp`` (:func:`cell_increment`, :func:`sinh_cosh`) and the constants taken
out of the sample loop (:func:`cell_constants`). Every mPL loop (runs, blocks, the fit's
passes) and mpl-g's advance their cells with these, so they agree bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["cell_constants", "cell_increment", "constants", "current", "sinh_cosh",
           "sinh_series", "straight_offset"]


@njit(cache=True, inline="always")
def current(v, i_s, v_t, knee, cap):
    """Limited sinh resistor current and its slope at ``v`` (libm's sinh; the linearisation and
    mpl-g's kernels use it, the mPL runs :func:`cell_increment`)."""
    if abs(v) <= knee:
        return 2.0 * i_s * np.sinh(v / v_t), 2.0 * i_s / v_t * np.cosh(v / v_t)
    s = 1.0 if v > 0 else -1.0
    return s * 2.0 * i_s * np.sinh(knee / v_t) + cap * (v - s * knee), cap


@njit(cache=True, inline="always")
def sinh_series(a):
    """``sinh a`` for ``|a| < 0.5``: ``a (1 + a^2 / 3! + ... + a^14 / 15!)``, the next term below
    5e-20 relative; pairs of terms (Estrin's scheme), so that its latency hides under the
    ``exp`` computed beside it."""
    a2 = a * a
    a4 = a2 * a2
    a8 = a4 * a4
    p01 = 1.0 + a2 * (1.0 / 6.0)
    p23 = 1.0 / 120.0 + a2 * (1.0 / 5040.0)
    p45 = 1.0 / 362880.0 + a2 * (1.0 / 39916800.0)
    p67 = 1.0 / 6227020800.0 + a2 * (1.0 / 1307674368000.0)
    return a * ((p01 + a4 * p23) + a8 * (p45 + a4 * p67))


@njit(cache=True, inline="always")
def sinh_cosh(a):
    """``(sinh a, cosh a)`` from one ``exp``: a few ulp from libm's, at half the cost.

    libm's ``sinh`` is the recursion's most expensive operation (its ``expm1`` and case
    analysis cost about twice an ``exp``), and the sensitivities need ``cosh`` as well. ``cosh =
    (e + 1/e) / 2`` has no cancellation; ``sinh = (e - 1/e) / 2`` loses ``coth a`` ulp to it,
    so for ``|a| < 0.5`` (where ``coth a > 2.2``) ``sinh`` comes from its series. Without it a
    nearly linear cell (``V_T ~ 1e3``, as fits give) would be 1e-13 off at every step.
    """
    t = abs(a)  # both are even or odd: e >= 1, so 1 / e neither divides by 0 nor overflows
    e = np.exp(t)
    e_inv = 1.0 / e
    # both computed, one selected: a data-dependent branch here mispredicts often
    sh = sinh_series(a) if t < 0.5 else math.copysign(0.5 * (e - e_inv), a)
    return sh, 0.5 * (e + e_inv)


@njit(cache=True, inline="always")
def cell_constants(i_s, v_t, knee, cap, dt):
    """What a cell's update needs that does not change per sample: ``1 / V_T``, ``2 I_S dt`` and
    ``c0 = (f(knee) - cap knee) dt``, with which the straight branch beyond the knee is
    ``f dt = s c0 + cap dt v`` (``s`` the sign of ``v``). Every caller computes them with this
    one function, so that runs and blocks advance their cells bit for bit alike."""
    return 1.0 / v_t, 2.0 * i_s * dt, straight_offset(i_s, v_t, knee, cap, dt)


@njit(cache=True, inline="always")
def straight_offset(i_s, v_t, knee, cap, dt):
    """``c0`` of :func:`cell_constants` (0 without a knee: the sinh everywhere)."""
    return (2.0 * i_s * np.sinh(knee / v_t) - cap * knee) * dt if knee < np.inf else 0.0


@njit(cache=True, inline="always")
def cell_increment(v, inv_vt, two_i_s_dt, knee, c0, cap_dt):
    """``f(v) dt`` of the limited sinh resistor (eq. 5.1, 5.29): one ``exp`` inside the knee."""
    if abs(v) <= knee:
        return two_i_s_dt * sinh_cosh(v * inv_vt)[0]
    return (c0 if v > 0 else -c0) + cap_dt * v


@njit(cache=True)
def constants(i_s, v_t, knee, cap, dt):
    """:func:`cell_constants` of every cell, as arrays ``(1 / V_T, 2 I_S dt, c0)``."""
    n = i_s.size
    inv_vt, two_i_s_dt, c0 = np.empty(n), np.empty(n), np.empty(n)
    for k in range(n):
        inv_vt[k], two_i_s_dt[k], c0[k] = cell_constants(i_s[k], v_t[k], knee[k], cap, dt)
    return inv_vt, two_i_s_dt, c0
