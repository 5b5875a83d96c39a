"""Linear analysis of the loop (fig. 7.4, 7.9): margins, Bode data, PID tuning, DOB design.

The loop is linearised at an operating point (a :class:`LoopState`; default: at rest, the
document's "t = 0") by :func:`~hystkit.control.open_loop` (``_linearise.py``), cut at the plant
input: ``L(z) = -v / u_p`` with ``u_p`` the force entering the plant and ``v`` the force the
controller (with DOB) returns, so the closed loop is ``feedback(L, 1)``. Margins and crossover
are read on the exact frequency response (:func:`loop_margins`).
"""

from __future__ import annotations

from dataclasses import replace

import control
import numpy as np
from scipy.optimize import brentq

from .._docfill import docfiller
from ._blocks import PID, TS, DisturbanceObserver, Plant, plant_matrices
from ._linearise import classify_poles, open_loop, slowest_cell, static_sign_flips
from ._loop import ControlLoop, LoopState
from ._loop_margins import LoopMargins

__all__ = ["DOB_CANDIDATES_HZ", "bode_data", "design_dob", "loop_margins", "tune_pid"]

# The loop and operating point the analyses take (the docstrings' %(operating_point)s).
ANALYSIS_ENTRIES = {
    "operating_point": """Parameters
----------
loop : ControlLoop
    The loop to analyse.
state : LoopState, optional
    Operating point; default :func:`rest_state` at ``r = 0``.""",
}
fill_analysis_doc = docfiller(ANALYSIS_ENTRIES.__getitem__)


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


@fill_analysis_doc
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

    %(operating_point)s

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


@fill_analysis_doc
def bode_data(loop: ControlLoop, state: LoopState | None = None,
              f: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frequency [Hz], magnitude [dB] and unwrapped phase [deg] of :func:`open_loop`.

    Default grid: 400 log-spaced points from 0.05 Hz to 0.95 of the Nyquist frequency. The
    unwrapped phase is shifted by whole turns so that it lies in (-360, 0] where ``|L|`` is
    closest to 1 (the crossover reads as ``-180 + phase margin``).

    %(operating_point)s
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
