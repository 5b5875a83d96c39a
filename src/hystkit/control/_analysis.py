"""Linear analysis of the loop (fig. 7.4, 7.9): linearised open loop, Bode, margins, tuning.

The loop is linearised at an operating point (a :class:`LoopState`; default: at rest, the
document's "t = 0"): the plant and PID are linear already, each mPL block is linearised as in
paper 9.2 eq. 2-7 (:meth:`SensorBlock.linearise`), and the DOB is its extended-state observer.
The open loop is cut at the plant input: ``L(z) = -v / u_p`` with ``u_p`` the force entering the
plant and ``v`` the force the controller (with DOB) returns, so the closed loop is
``feedback(L, 1)``. Margins and crossover come from python-control's ``stability_margins``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import control
import numpy as np
import scipy.linalg
from scipy.optimize import brentq

from ._blocks import (
    PID,
    TS,
    DisturbanceObserver,
    Plant,
    extended_input,
    extended_matrices,
    plant_matrices,
)
from ._loop import ControlLoop, LoopState, rest_state

__all__ = ["LoopMargins", "bode_data", "classify_poles", "design_dob", "loop_margins", "open_loop",
           "slowest_cell", "static_sign_flips", "tune_pid"]


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


@dataclass(frozen=True)
class LoopMargins:
    """Crossover and stability margins of the linearised loop.

    Parameters
    ----------
    crossover_hz : float or None
        Gain-crossover frequency ``|L| = 1`` [Hz] (None if ``|L|`` never crosses 1).
    phase_margin_deg : float or None
        Phase margin at the crossover [deg]; None without a crossover.
    gain_margin_db : float or None
        Gain margin ``-20 log10 |L|`` [dB] at the phase crossing (``arg L = -180`` deg) that
        limits the gain from above (see :func:`loop_margins`; negative for an unstable loop
        whose gain is too high); None when no crossing limits it (infinite gain margin).
    phase_crossover_hz : float or None
        Phase-crossover frequency [Hz] at which the gain margin is read.
    closed_loop_stable : bool
        All poles of ``feedback(L, 1)`` strictly inside the unit circle.
    max_pole_radius : float
        Largest ``|pole|`` of the closed loop.
    growth_time_s : float or None
        For an unstable loop, the e-folding time ``Ts / ln max|pole|`` [s] of its fastest
        growing mode: a slow drift (hours) and a blow-up (milliseconds) both count as unstable.
        None when no pole lies outside the unit circle (beyond its rounding).
    cause : str or None
        For an unstable loop, a known cause in words (:func:`static_sign_flips`), else None.
    slow_cell : str or None
        For a loop whose growth is no faster than the slowest cell of its sensor and
        compensator blocks decays (``growth_time_s`` at least that cell's time constant: the
        pole lies outside the unit circle by no more than the cell's pole lies inside it), the
        block with that cell; the growing mode is a marginal one from a slow cell, see
        :func:`slow_cell_words`. None otherwise.
    slow_cell_s : float or None
        That cell's time constant [s]; None with `slow_cell`.
    marginal : bool
        No pole outside the unit circle and at least one on it (within the rounding of its
        eigenvalue, see :func:`classify_poles`): a state the linearised loop neither corrects
        nor amplifies, e.g. a friction element or a dead band of a sensor model that holds its
        state at rest, or a double integrator.
    """

    crossover_hz: float | None
    phase_margin_deg: float | None
    gain_margin_db: float | None
    phase_crossover_hz: float | None
    closed_loop_stable: bool
    max_pole_radius: float
    growth_time_s: float | None = None
    marginal: bool = False
    cause: str | None = None
    slow_cell: str | None = None
    slow_cell_s: float | None = None

    def to_dict(self) -> dict:
        """The fields as a dict (JSON-safe: floats, bools and None)."""
        return dict(vars(self))


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


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def _grid(ts: float, f_min: float = 1e-3, n: int = 4000) -> np.ndarray:
    return np.geomspace(f_min, 0.999 * 0.5 / ts, n)


def _gain_margin(h, f: np.ndarray, resp: np.ndarray,
                 unstable: bool) -> tuple[float | None, float | None]:
    """Gain margin [dB] and its phase-crossover frequency [Hz] (see :func:`loop_margins`)."""
    im = resp.imag
    margins = []  # (gain margin [dB], frequency [Hz]) at each crossing of arg L = -180 mod 360
    for j in np.nonzero(np.sign(im[:-1]) != np.sign(im[1:]))[0]:
        if resp[j].real >= 0 and resp[j + 1].real >= 0:
            continue  # arg L = 0: the Nyquist curve crosses the positive real axis
        f_pc = brentq(lambda x: h(x).imag, f[j], f[j + 1], xtol=1e-12 * f[j])
        h_pc = h(f_pc)
        if h_pc.real < 0 and h_pc != 0:
            margins.append((float(-20 * np.log10(abs(h_pc))), float(f_pc)))
    above = [m for m in margins if m[0] > 0]
    if above:
        return min(above)
    if unstable and margins:  # the gain is too high: the reduction back to the last crossing
        return max(margins)
    return None, None


def loop_margins(loop: ControlLoop, state: LoopState | None = None) -> LoopMargins:
    """Margins of :func:`open_loop` and closed-loop stability of the linearised loop.

    The crossover is the highest frequency with ``|L| = 1`` and the phase margin is
    ``180 + arg L`` there. The gain margin is ``-20 log10 |L|`` at a phase crossing
    (``arg L = -180`` mod 360, where a gain ``1 / |L|`` puts a closed-loop pole on the unit
    circle): the crossing with the largest ``|L| < 1``, the factor by which the gain can grow
    (a crossing with ``|L| > 1``, e.g. the low-frequency one of a double integrator with
    integral action, bounds the gain from below and is not the margin). An unstable loop
    without such a crossing has too much gain: its margin is negative, read at the crossing
    with the smallest ``|L| > 1`` (the reduction back to it). Crossings are found on a
    4000-point log grid (1 mHz to Nyquist) and refined by root finding on the exact frequency
    response.
    python-control's ``stability_margins`` is not used: the loop's three poles at ``z = 1``
    (plant and integrator) make its polynomial method fall back to a grid that returns
    spurious low-frequency crossings.

    Parameters
    ----------
    loop : ControlLoop
        The loop to analyse.
    state : LoopState, optional
        Operating point; default :func:`rest_state` at ``r = 0``.

    Returns
    -------
    LoopMargins
        Crossover, margins and the closed-loop pole classification.
    """
    lsys = open_loop(loop, state)
    growth, stable, marginal, radius = classify_poles(control.feedback(lsys, 1).A)
    growth_time = float(loop.ts / np.log(growth)) if growth > 1 else None

    def h(f: float) -> complex:
        return complex(np.asarray(lsys(np.exp(2j * np.pi * f * loop.ts))).reshape(-1)[0])

    f = _grid(loop.ts)
    resp = np.asarray(control.frequency_response(lsys, 2 * np.pi * f).complex).reshape(-1)
    # |L| = 0 exactly when the compensator is constant (a collapsed fit): no crossover
    log_mag = np.log(np.maximum(np.abs(resp), np.finfo(float).tiny))
    cross = np.nonzero(np.sign(log_mag[:-1]) != np.sign(log_mag[1:]))[0]
    f_c = pm = None
    if cross.size:
        i = cross[-1]
        f_c = brentq(lambda x: np.log(abs(h(x))), f[i], f[i + 1], xtol=1e-12 * f[i])
        pm = float(np.degrees(np.angle(-h(f_c))))
    gm, f_pc = _gain_margin(h, f, resp, unstable=growth_time is not None)
    slow = slowest_cell(loop, state) if growth_time is not None else None
    if slow is not None and growth_time < slow[1]:
        slow = None  # faster than every cell: not the slow cell's, a real instability
    return LoopMargins(crossover_hz=f_c, phase_margin_deg=pm, gain_margin_db=gm,
                       phase_crossover_hz=f_pc, closed_loop_stable=stable,
                       max_pole_radius=radius,
                       growth_time_s=growth_time, marginal=marginal,
                       cause=("; ".join(static_sign_flips(loop, state, growth_time)) or None)
                       if growth_time is not None else None,
                       slow_cell=None if slow is None else slow[0],
                       slow_cell_s=None if slow is None else slow[1])


def bode_data(loop: ControlLoop, state: LoopState | None = None,
              f: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frequency [Hz], magnitude [dB] and unwrapped phase [deg] of :func:`open_loop`.

    Default grid: 400 log-spaced points from 0.05 Hz to 0.95 of the Nyquist frequency. The
    unwrapped phase is shifted by whole turns so that it lies in (-360, 0] where ``|L|`` is
    closest to 1 (the crossover reads as ``-180 + phase margin``).

    Parameters
    ----------
    loop : ControlLoop
        The loop to analyse.
    state : LoopState, optional
        Operating point; default :func:`rest_state` at ``r = 0``.
    f : numpy.ndarray, optional
        Frequencies [Hz]; default the grid above.

    Returns
    -------
    f : numpy.ndarray, shape (n,)
        Frequency [Hz].
    magnitude_db : numpy.ndarray, shape (n,)
        ``20 log10 |L|`` [dB].
    phase_deg : numpy.ndarray, shape (n,)
        Unwrapped phase of ``L`` [deg].
    """
    if f is None:
        f = np.geomspace(0.05, 0.95 * 0.5 / loop.ts, 400)
    resp = control.frequency_response(open_loop(loop, state), 2 * np.pi * np.asarray(f))
    h = np.asarray(resp.complex).reshape(-1)
    phase = np.degrees(np.unwrap(np.angle(h)))
    phase -= 360.0 * np.ceil(phase[np.argmin(np.abs(np.log(np.abs(h))))] / 360.0)
    return f, 20 * np.log10(np.abs(h)), phase


def _response(num, den, z):
    return np.polyval(num, z) / np.polyval(den, z)


def tune_pid(f_c: float, phase_margin: float = 60.0, *, loop: ControlLoop | None = None,
             plant: Plant | None = None, ts: float = TS, ti_over_td: float = 4.0,
             tf_over_td: float = 0.0) -> PID:
    """Eq. 7.2 PID whose loop crosses over at ``f_c`` [Hz] with ``phase_margin`` [deg].

    The loop tuned is ``C(z) G(z)``. Without ``loop``, ``G`` is the exact ZOH plant alone: the
    linear loop the document tunes on (sec. 7.2). With ``loop``, ``G`` is that loop's
    linearised open loop at rest with ``C = 1`` and no DOB -- plant, sensor, compensator or the
    scheme (b) sensor gain included -- so the target holds for the loop as simulated (at rest).
    With ``Ti = ti_over_td * Td`` (4: a double real zero in continuous time) and
    ``Tf = tf_over_td * Td``, ``Td`` is solved so that ``arg C G = -180 + phase_margin`` at
    ``f_c`` (the PID's phase rises monotonically with ``Td``), then ``Kp`` so that
    ``|C G| = 1`` there. Check the result with :func:`loop_margins`: a path with its own
    dynamics can add crossings elsewhere.

    Parameters
    ----------
    f_c : float
        Target crossover frequency [Hz].
    phase_margin : float, default 60.0
        Target phase margin [deg].
    loop : ControlLoop, optional
        Tune on this loop's linearised open loop at rest; default the plant alone.
    plant : Plant, optional
        Plant to tune on when `loop` is None; default :class:`Plant` ().
    ts : float, default TS
        Sample time [s] when `loop` is None (a loop brings its own).
    ti_over_td : float, default 4.0
        Ratio ``Ti / Td``.
    tf_over_td : float, default 0.0
        Ratio ``Tf / Td`` (derivative filter; 0 is eq. 7.2 exactly).

    Returns
    -------
    PID
        The tuned controller.

    Raises
    ------
    ValueError
        If no ``Td`` gives that much phase (the PID's lead stays below 90 deg).
    """
    z = np.exp(2j * np.pi * f_c * (ts if loop is None else loop.ts))
    if loop is None:
        plant = Plant() if plant is None else plant
        a, b, c = plant_matrices(plant.mass, ts)
        g = complex(c @ np.linalg.solve(z * np.eye(2) - a, b))
    else:
        ts = loop.ts
        unit = open_loop(replace(loop, pid=PID(kp=1.0), dob=None))
        g = complex(np.asarray(unit(z)).reshape(-1)[0])
    phase_g = np.angle(g)
    if phase_g > 0:  # the double integrator sits at -180 deg: keep its branch
        phase_g -= 2 * np.pi
    need = -np.pi + np.radians(phase_margin) - phase_g

    def pid_for(td: float, kp: float = 1.0) -> PID:
        return PID(kp=kp, ti=ti_over_td * td, td=td, tf=tf_over_td * td)

    def mismatch(log_td: float) -> float:
        return float(np.angle(_response(*pid_for(np.exp(log_td)).transfer_coefficients(ts), z))
                     - need)

    lo, hi = np.log(1e-3 / (2 * np.pi * f_c)), np.log(1e3 / (2 * np.pi * f_c))
    if not (mismatch(lo) < 0 < mismatch(hi)):
        raise ValueError(f"a PID of this form cannot give {phase_margin} deg of phase margin at "
                         f"{f_c} Hz (it needs {np.degrees(need):.1f} deg of lead)")
    td = float(np.exp(brentq(mismatch, lo, hi, xtol=1e-12)))
    gain = abs(_response(*pid_for(td).transfer_coefficients(ts), z) * g)
    return pid_for(td, 1.0 / gain)


DOB_CANDIDATES_HZ = tuple(float(f) for f in np.round(np.geomspace(1.0, 200.0, 24), 3))


def design_dob(loop: ControlLoop, *, min_phase_margin: float = 30.0,
               min_gain_margin_db: float = 6.0, candidates_hz=DOB_CANDIDATES_HZ,
               state: LoopState | None = None) -> DisturbanceObserver:
    """Choose the Q-filter bandwidth: the highest candidate that keeps the margins.

    Steps 1-2 of the procedure are fixed by :class:`DisturbanceObserver` (nominal plant, binomial
    ``Q = 1 / (tau s + 1)^3``). Step 3: for each candidate ``f_q`` (default 24 log-spaced values, 1-200 Hz, the
    top a fifth of the Nyquist frequency) the loop with that DOB is linearised at ``state``,
    sensor and compensator included, and the highest ``f_q`` is kept whose loop has at least
    ``min_phase_margin`` [deg] and ``min_gain_margin_db`` [dB] and no closed-loop pole further
    out than the loop without the DOB (or than the unit circle, whichever is larger): the DOB
    must not destabilise. A higher bandwidth rejects more disturbance but feeds more of the
    sensor-compensator mismatch back into the plant.

    Parameters
    ----------
    loop : ControlLoop
        The loop (its own DOB, if any, is replaced by each candidate).
    min_phase_margin : float, default 30.0
        Least phase margin [deg].
    min_gain_margin_db : float, default 6.0
        Least gain margin [dB].
    candidates_hz : sequence of float, default DOB_CANDIDATES_HZ
        Q-filter bandwidths to try [Hz].
    state : LoopState, optional
        Operating point of the linearisation; default :func:`rest_state` at ``r = 0``.

    Returns
    -------
    DisturbanceObserver
        The DOB with the highest admissible bandwidth and the loop's nominal mass.

    Raises
    ------
    ValueError
        If no candidate keeps the margins.
    """
    base = loop_margins(replace(loop, dob=None), state)
    limit = max(1.0, base.max_pole_radius) + 1e-12
    best = None
    for f_q in candidates_hz:
        dob = DisturbanceObserver(float(f_q), loop.nominal_mass)
        m = loop_margins(_with_dob(loop, dob), state)
        ok = (m.max_pole_radius <= limit
              and (m.phase_margin_deg is None or m.phase_margin_deg >= min_phase_margin)
              and (m.gain_margin_db is None or m.gain_margin_db >= min_gain_margin_db))
        if ok:
            best = dob
    if best is None:
        raise ValueError("no Q-filter bandwidth keeps the required margins on this loop")
    return best


def _with_dob(loop: ControlLoop, dob: DisturbanceObserver) -> ControlLoop:
    return replace(loop, dob=dob)
