"""The closed loop as one compiled kernel: every block, every step, no Python per sample.

``_loop.py`` holds the validating wrapper and the readable plain-Python reference that this
kernel must match. Arrays are float64 and validated by the caller.

The three model slots (S_r, compensator, S_m) take any family's compiled block step
(``hystkit.models.Block``): numba specialises :func:`run` once per combination of step
functions. A combination is compiled once (about a second) into numba's on-disk cache, keyed
by the steps' names and the stamps of the files that define them, and later processes load it
(a few milliseconds); a step without a stable name (a closure, a function of ``__main__``) gets
a loop compiled in this process only.

State vector (explicit, in and out)::

    0 plant position [m]      1 plant velocity [m/s]
    2 PID integral            3 PID previous error      4 PID derivative term
    5 plant-estimate position 6 plant-estimate velocity (fig. 7.11, nominal plant)
    7-9 DOB estimates of position, velocity, input force (sec. 7.4)
    then the states of S_r, of the compensator and of S_m

Signals recorded per step (rows of ``out``): see :data:`SIGNALS`.
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit, typeof

from .._closure_cache import compile_closure

N_FIXED = 10
SIGNALS = ("y", "s", "y_hat", "s_hat", "y_hat_plant", "e", "u", "d_hat")
STOP_REASONS = {1: "plant position non-finite or beyond the position limit",
                2: "control effort non-finite",
                3: "sensor, model or compensator signal non-finite"}


@njit(cache=True)
def identity_step(body, x, xn, off, u):
    """The ideal memoryless block (no state): output = normalised input."""
    return u


_COMPILED: dict = {}


def run(r, d_out, d_in, noise, x0, direct, plant, pid, dob, y_limit, sizes, step_r, aff_r,
        body_r, step_c, aff_c, body_c, step_m, aff_m, body_m):
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
    sizes : int array, shape (5,)
        State lengths of S_r, compensator, S_m, then 1/0 for compensator and S_m present.
    step_*, aff_*, body_* : block step function, ``[a_in, b_in, a_out, b_out]``, parameters
        Of S_r, the compensator and S_m (``SensorBlock.pack``); an absent slot gets
        :func:`identity_step` and is not called.

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
    return _kernel(step_r, step_c, step_m)(r, d_out, d_in, noise, x0, direct, plant, pid, dob,
                                           y_limit, sizes, aff_r, body_r, aff_c, body_c,
                                           aff_m, body_m)


def compile_run(r, d_out, d_in, noise, x0, direct, plant, pid, dob, y_limit, sizes, step_r,
                aff_r, body_r, step_c, aff_c, body_c, step_m, aff_m, body_m) -> float:
    """Compile :func:`run` for these arguments' types unless done in this process; the
    seconds it took (0.0 when already compiled). Called before a timed :func:`run`, so that the
    run's time is the simulation's alone (the first run of a combination of block steps would
    otherwise count about a second of JIT compilation)."""
    kernel = _kernel(step_r, step_c, step_m)
    args = (r, d_out, d_in, noise, x0, direct, plant, pid, dob, y_limit, sizes, aff_r, body_r,
            aff_c, body_c, aff_m, body_m)
    signature = tuple(typeof(a) for a in args)
    if signature in kernel.overloads:
        return 0.0
    t_start = time.perf_counter()
    kernel.compile(signature)
    return time.perf_counter() - t_start


def _kernel(step_r, step_c, step_m):
    key = (step_r, step_c, step_m)
    if key not in _COMPILED:
        _COMPILED[key] = compile_closure(_make(*key), key)
    return _COMPILED[key]


def _make(step_r, step_c, step_m):
    """The loop for one combination of block steps, to be compiled by numba. They are closure
    constants, so numba inlines them into the loop (as an argument, each call would cost a
    function call and the reference counting of its arrays: measured 12 % slower on the mPL
    loop)."""

    def loop(r, d_out, d_in, noise, x0, direct, plant, pid, dob, y_limit, sizes, aff_r, body_r,
             aff_c, body_c, aff_m, body_m):

        n_steps = r.size
        out = np.zeros((8, n_steps))
        x = x0.copy()
        xn = x0.copy()
        ts, b1, b2, b1n, b2n, u_max = plant[0], plant[1], plant[2], plant[3], plant[4], plant[5]
        kp, ki, td, tf, anti_windup, g_s = pid[0], pid[1], pid[2], pid[3], pid[4] != 0.0, pid[5]
        use_dob = dob[0] != 0.0
        has_c = sizes[3] != 0
        has_m = sizes[4] != 0
        off_r = N_FIXED
        off_c = off_r + sizes[0]
        off_m = off_c + sizes[1]
        for n in range(n_steps):
            for i in range(x.size):
                xn[i] = x[i]
            y = x[0] + d_out[n]
            s = aff_r[2] * step_r(body_r, x, xn, off_r, aff_r[0] * y + aff_r[1]) + aff_r[3]
            s += noise[n]
            y_hat = 0.0
            if has_c:
                y_hat = aff_c[2] * step_c(body_c, x, xn, off_c, aff_c[0] * s + aff_c[1]) \
                    + aff_c[3]
            s_hat = 0.0
            if has_m:
                s_hat = aff_m[2] * step_m(body_m, x, xn, off_m, aff_m[0] * r[n] + aff_m[1]) \
                    + aff_m[3]
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

    return loop
