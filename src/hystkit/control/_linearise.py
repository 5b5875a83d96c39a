"""The loop linearised at an operating point, as python-control state-space blocks.

The plant and PID are linear already, each sensor block is linearised by its family
(:meth:`SensorBlock.linearise`; the mPL as in paper 9.2 eq. 2-7), and the DOB is its
extended-state observer. :func:`open_loop` cuts the loop at the plant input; the poles of the
blocks and of the closed loop are read here too (:func:`classify_poles`, :func:`slowest_cell`,
:func:`static_sign_flips`). Margins, Bode data and tuning built on it: ``_analysis.py``.
"""

from __future__ import annotations

import control
import numpy as np
import scipy.linalg

from ._blocks import extended_input, extended_matrices, plant_matrices
from ._loop import ControlLoop, LoopState, rest_state

__all__ = ["MARGINAL", "classify_poles", "open_loop", "slowest_cell", "static_sign_flips"]


def _ss(a, b, c, d, ts, inputs, outputs, name) -> control.StateSpace:
    n = np.size(a) and np.atleast_2d(a).shape[0]
    n_in = 1 if isinstance(inputs, str) else len(inputs)
    a = np.reshape(np.asarray(a, dtype=float), (n, n))
    b = np.reshape(np.asarray(b, dtype=float), (n, n_in))
    c = np.reshape(np.asarray(c, dtype=float), (1, n))
    d = np.reshape(np.asarray(d, dtype=float), (1, n_in))
    return control.ss(a, b, c, d, ts, inputs=inputs, outputs=outputs, name=name)


def _read_states(a: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Mask of the states the block's output depends on, directly or through other states.

    A state that neither the output nor any other state reads (a Preisach staircase entry, a
    play inside its band at this operating point) cannot change any signal of the loop; it is
    dropped so that the analysis costs what the block's dynamics cost, not its memory (a
    1024-entry staircase would make the loop a 1040-state system).
    """
    keep = c != 0
    while True:
        grown = keep | np.any(a[keep] != 0, axis=0)  # what the kept states' updates read
        if np.array_equal(grown, keep):
            return keep
        keep = grown


def _block_ss(block, x, u_in, ts, inputs, outputs, name) -> control.StateSpace:
    a, b, c, d = block.linearise(x, u_in, ts)
    a = np.atleast_2d(np.asarray(a, dtype=float)).reshape(np.size(c), np.size(c))
    c = np.asarray(c, dtype=float).reshape(-1)
    keep = _read_states(a, c)
    return _ss(a[np.ix_(keep, keep)], np.asarray(b, dtype=float).reshape(-1)[keep], c[keep],
               d, ts, inputs, outputs, name)


def open_loop(loop: ControlLoop, state: LoopState | None = None) -> control.StateSpace:
    """Linearised open loop ``L(z)`` cut at the plant input (discrete, ``dt = loop.ts``).

    Parameters
    ----------
    loop : ControlLoop
        The loop to linearise.
    state : LoopState, optional
        Operating point; default :func:`rest_state` at ``r = 0``. The sensor blocks'
        slopes are taken at their state and at the inputs that state implies (the plant
        position, then the sensor's output).

    Returns
    -------
    control.StateSpace
        ``L(z)``, input ``u_p`` [N], output ``v`` [N], sample time ``loop.ts``.
    """
    blocks = _blocks(loop, state)
    sys = control.interconnect(blocks, inplist=["u_p"], outlist=["v"], name="open_loop")
    return control.ss(sys.A, sys.B, -sys.C, -sys.D, loop.ts, inputs="u_p", outputs="v",
                      name="L")


def _blocks(loop: ControlLoop, state: LoopState | None) -> list:
    """The loop's linearised blocks, named, for ``control.interconnect``."""
    state = rest_state(loop) if state is None else state
    ts = loop.ts
    a, b, c = plant_matrices(loop.plant.mass, ts)
    blocks = [_ss(a, b, c, 0.0, ts, "u_p", "y", "plant")]
    y0 = float(state.plant[0])
    blocks.append(_block_ss(loop.sensor, state.sensor, y0, ts, "y", "s", "sensor"))
    s0, _ = loop.sensor.step(state.sensor, y0, ts)
    if loop.scheme == "direct" or loop.dob is not None:  # else y_hat is not fed back
        blocks.append(_block_ss(loop.compensator, state.compensator, s0, ts, "s", "y_hat",
                                "compensator"))
    if loop.scheme == "direct":
        blocks.append(control.summing_junction(["-y_hat"], "e", name="error"))
    else:
        blocks.append(_ss([], [], [], -loop.sensor_gain, ts, "s", "e", "error"))
    num, den = loop.pid.transfer_coefficients(ts)
    pid = control.tf2ss(control.tf(num, den, ts))
    blocks.append(_ss(pid.A, pid.B, pid.C, pid.D, ts, "e", "u_c", "pid"))
    if loop.dob is None:
        blocks.append(control.summing_junction(["u_c"], "v", name="force"))
    else:
        a_e, c_e = extended_matrices(loop.mass_n, ts)
        gain = loop.dob.observer_gain(loop.mass_n, ts)
        b_e = extended_input(loop.mass_n, ts)
        blocks.append(_ss(a_e - np.outer(gain, c_e), np.column_stack([gain, b_e]),
                          [0.0, 0.0, 1.0], [[0.0, 0.0]], ts, ["y_hat", "v"], "d_hat", "dob"))
        blocks.append(control.summing_junction(["u_c", "-d_hat"], "v", name="force"))
    return blocks


def static_sign_flips(loop: ControlLoop, state: LoopState | None = None,
                      growth_time_s: float | None = None) -> list[str]:
    """Why a loop can be unstable only at time scales far beyond its runs, in words.

    A sensor model or compensator whose static gain has the opposite sign of its
    instantaneous gain (``D``) has a real zero beyond ``z = 1``: its slowest cell undoes, and
    overshoots, the direct path over a time much longer than the training data. The loop's
    integral action (the plant's double integrator, the PID's integrator) pulls a closed-loop
    pole towards that zero, so the linearised loop drifts away with an e-folding time of
    hours to days while every run of seconds to minutes stays bounded.

    Parameters
    ----------
    loop : ControlLoop
    state : LoopState, optional
        Operating point; default :func:`rest_state` at ``r = 0``.
    growth_time_s : float, optional
        The loop's e-folding time [s]: only a flip that can explain it is named, a block
        whose slowest cell is no slower than the growth (the pole such a flip pulls beyond
        ``z = 1`` grows more slowly than that cell decays). A faster blow-up has another
        cause (e.g. gains), and the flip is not named for it.

    Returns
    -------
    list of str
        One sentence per block (sensor, compensator) with such a sign flip; empty if none.
    """
    notes = []
    for sys in _blocks(loop, state):
        if sys.name not in ("sensor", "compensator") or sys.nstates == 0:
            continue
        direct = float(np.asarray(sys.D).reshape(-1)[0])
        poles = np.abs(np.linalg.eigvals(sys.A))
        if poles.max() >= 1.0 or direct == 0.0:
            continue
        static = float(np.real(control.dcgain(sys)))
        slowest = -loop.ts / np.log(poles.max())
        if np.sign(static) != np.sign(direct) and (growth_time_s is None
                                                   or growth_time_s >= slowest):
            notes.append(f"the {sys.name} has a static gain ({static:.3g}) of the opposite "
                         f"sign to its instantaneous gain ({direct:.3g}): its slowest cell (time "
                         f"constant {slowest:.3g} s) overturns it, a zero beyond z = 1 that "
                         f"the integral action of the loop pulls a pole onto")
    return notes


MARGINAL = 1e-12
"""Least tolerance on a pole radius for counting it on the unit circle."""


def slowest_cell(loop: ControlLoop, state: LoopState | None = None) -> tuple[str, float] | None:
    """The slowest decaying cell of the loop's sensor and compensator blocks: their
    linearisation's pole nearest to, and inside, the unit circle.

    Parameters
    ----------
    loop : ControlLoop
        The closed loop.
    state : LoopState, optional
        The operating point to linearise at (default: the loop's rest state).

    Returns
    -------
    tuple of (str, float) or None
        ``(block, time constant [s])``; None when the blocks have no state or none inside
        the circle.
    """
    slowest = None
    for sys in _blocks(loop, state):
        if sys.name not in ("sensor", "compensator") or sys.nstates == 0:
            continue
        radii = np.abs(np.linalg.eigvals(sys.A))
        inside = radii[(radii < 1.0) & (radii > 0.0)]
        if inside.size:
            tau = float(-loop.ts / np.log(inside.max()))
            if slowest is None or tau > slowest[1]:
                slowest = (sys.name, tau)
    return slowest


def classify_poles(a: np.ndarray) -> tuple[float, bool, bool, float]:
    """``(growth radius, stable, marginal, max |pole|)`` of the discrete system ``x+ = A x``.

    A pole is beyond the unit circle only when its radius exceeds 1 by more than the rounding
    of that eigenvalue, ``100 eps ||A|| kappa`` with ``kappa = 1 / |y^H x|`` its condition
    number (unit left and right eigenvectors; at least ``MARGINAL``): a double integrator's two
    poles at 1 come out as 1 +- 1e-8 with ``kappa`` ~ 1e8, a nearly defective pair 1e-5 apart as
    1 + 6e-10. The tolerance is capped at a double pole's rounding, ``10 sqrt(eps ||A||)``.
    A pole is on the circle when not beyond it and within that rounding below 1. The growth
    radius is the largest radius beyond the circle (1.0 when there is none).

    Parameters
    ----------
    a : numpy.ndarray, shape (n, n)
        State matrix of the discrete system (an empty matrix is a stable system).

    Returns
    -------
    growth : float
        Largest pole radius beyond the unit circle, 1.0 when there is none.
    stable : bool
        Every pole strictly inside the circle (beyond its rounding).
    marginal : bool
        No pole beyond the circle and at least one on it.
    max_radius : float
        Largest ``|pole|`` (0.0 for an empty matrix).
    """
    a = np.atleast_2d(np.asarray(a, dtype=float))
    if a.size == 0:
        return 1.0, True, False, 0.0
    poles, left, right = scipy.linalg.eig(a, left=True, right=True)
    eps, norm = np.finfo(float).eps, np.linalg.norm(a, 2)
    kappa = 1.0 / np.maximum(np.abs(np.sum(left.conj() * right, axis=0)), 1e-300)
    # capped at a double pole's rounding, sqrt(eps ||A||): an exactly defective pole has an
    # infinite kappa, and higher multiplicities are not resolved
    tol = np.clip(100 * eps * norm * kappa, MARGINAL, 10 * np.sqrt(eps * norm))
    radii = np.abs(poles)
    outside = radii > 1 + tol
    on = ~outside & (radii >= 1 - tol)
    growth = float(radii[outside].max()) if outside.any() else 1.0
    return (growth, not (outside.any() or on.any()), bool(on.any() and not outside.any()),
            float(radii.max()))
