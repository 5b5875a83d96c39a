"""Global stability of the loop beyond linearisation: slope sectors and the circle criterion.

The hysteretic blocks are replaced by what is known of them globally: the slope of their
input-output map. With the reference held constant, every linear block (plant, PID, DOB) acts
the same on the *increments* of its signals, and a block whose increments obey
``dv_n = k_n dy_n`` with ``k_1 <= k_n <= k_2`` is, for the increments, a time-varying gain in
the sector ``[k_1, k_2]``. The discrete circle criterion (Haddad & Bernstein 1994, part II;
Khalil, Nonlinear Systems, sec. 7.1 in continuous time) then proves that every increment decays
exponentially -- the loop comes to rest -- for every such gain sequence:

1. ``T_1 = G / (1 + k_1 G)`` is asymptotically stable (the linear loop at ``k_1``), and
2. ``Z = (1 + k_2 G) / (1 + k_1 G) = 1 + (k_2 - k_1) T_1`` is strictly positive real,
   i.e. ``Re Z(e^{jw}) > 0`` on the unit circle, i.e.
   ``k_2 < k_1 + 1 / max_w(-Re T_1(e^{jw}))``.

``G(z)`` is the loop's linear part seen by the nonlinearity (:func:`sector_channel`). The
criterion is *sufficient*: a loop it does not prove may still be stable. A loop is called
unstable only when a simulation shows it (:func:`global_stability`).

The sector is measured (:func:`measure_sector`): the block is driven over its training range
(the trained 0.5 Hz, 3 mm sine of sec. 7.2, at the loop's ``Ts``) and the chord slopes of
consecutive samples are taken where the input moves. A dynamic model (the mPL is an ODE) can
change its output while its input stands still; those samples are left out and how far they
fall outside the sector is reported, so the reader sees how much of the block the sector does
not describe. :func:`global_stability` widens it to the hull with the slopes of the experiment's
own closed-loop runs: a sector is only as good as the trajectories it was measured on, and the
proof holds only for slopes inside it.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np
from scipy.optimize import minimize_scalar

from ._blocks import extended_input, extended_matrices, plant_matrices
from ._experiments import run_experiment
from ._linearise import _ss, classify_poles
from ._loop import ControlLoop
from ._sectors import Sector, chord_sector, hull, interval, measure_sector

__all__ = ["CircleResult", "StabilityReport", "circle_criterion", "global_stability",
           "sector_channel"]

def sector_channel(loop: ControlLoop) -> control.StateSpace:
    """The linear part ``G(z)`` the loop's nonlinearity closes: ``y = -G v``, ``v = phi(y)``.

    ``phi`` is ``y -> y_hat`` (compensator after ``S_r``) in scheme ``direct`` and ``S_r``
    (``y -> s``) in ``weighting``; ``G`` holds PID, plant and, in ``direct``, the DOB (fed by
    ``y_hat``). The reference is held constant (increments). Discrete, ``dt = loop.ts``.

    Parameters
    ----------
    loop : ControlLoop
        The loop.

    Returns
    -------
    control.StateSpace
        ``G(z)``, input ``v``, output ``y`` [m].

    Raises
    ------
    ValueError
        Scheme ``weighting`` with the DOB: two nonlinear channels (``S_r`` into the PID, the
        compensator into the DOB), outside this single-channel criterion.
    """
    if loop.scheme == "weighting" and loop.dob is not None:
        raise ValueError("scheme weighting with the DOB has two nonlinear channels (S_r into "
                         "the PID, the compensator into the DOB); the circle criterion here "
                         "covers one")
    ts = loop.ts
    a, b, c = plant_matrices(loop.plant.mass, ts)
    num, den = loop.pid.transfer_coefficients(ts)
    pid = control.tf2ss(control.tf(num, den, ts))
    gain = -1.0 if loop.scheme == "direct" else -loop.sensor_gain
    blocks = [_ss(a, b, c, 0.0, ts, "u_p", "y", "plant"),
              _ss(pid.A, pid.B, pid.C, pid.D, ts, "e", "u_c", "pid"),
              _ss([], [], [], gain, ts, "v", "e", "error")]
    if loop.dob is None:
        blocks.append(control.summing_junction(["u_c"], "u_p", name="force"))
    else:
        a_e, c_e = extended_matrices(loop.mass_n, ts)
        l_gain = loop.dob.observer_gain(loop.mass_n, ts)
        blocks.append(_ss(a_e - np.outer(l_gain, c_e),
                          np.column_stack([l_gain, extended_input(loop.mass_n, ts)]),
                          [0.0, 0.0, 1.0], [[0.0, 0.0]], ts, ["v", "u_p"], "d_hat", "dob"))
        blocks.append(control.summing_junction(["u_c", "-d_hat"], "u_p", name="force"))
    sys = control.interconnect(blocks, inplist=["v"], outlist=["y"])
    return control.ss(sys.A, sys.B, -sys.C, -sys.D, ts, inputs="v", outputs="y", name="G")


@dataclass(frozen=True)
class CircleResult:
    """Verdict of the discrete circle criterion for ``G`` and the sector ``[k_min, k_max]``.

    Parameters
    ----------
    k_min, k_max : float
        The sector tested.
    proved : bool
        Conditions 1 and 2 of the module docstring hold.
    base_stable : bool
        Condition 1: ``G / (1 + k_min G)`` has every pole strictly inside the unit circle.
    k_max_proved : float or None
        The largest upper bound the criterion proves with this ``k_min`` (exclusive):
        ``k_min + 1 / max(-Re T_1)``; None when condition 1 fails, inf when ``-Re T_1`` never
        exceeds 0.
    worst_hz : float or None
        Frequency [Hz] of ``max(-Re T_1)``.
    """

    k_min: float
    k_max: float
    proved: bool
    base_stable: bool
    k_max_proved: float | None
    worst_hz: float | None

    def to_dict(self) -> dict:
        """The fields as a JSON-safe dict (an infinite ``k_max_proved`` as ``"inf"``)."""
        out = dict(vars(self))
        if out["k_max_proved"] is not None and not np.isfinite(out["k_max_proved"]):
            out["k_max_proved"] = "inf"
        return out


def circle_criterion(g: control.StateSpace, k_min: float, k_max: float, *,
                     n_grid: int = 20000) -> CircleResult:
    """Discrete circle criterion for ``y = -G v``, ``v = k_n y``, ``k_min <= k_n <= k_max``.

    ``max(-Re T_1)`` is searched on ``n_grid`` frequencies (log-spaced from 1e-6 of the
    Nyquist frequency, plus 0 and Nyquist) and refined by a bounded scalar search between the
    neighbours of the best grid point; ``T_1``'s frequency response is python-control's.

    Parameters
    ----------
    g : control.StateSpace
        Discrete-time linear part ``G(z)`` (:func:`sector_channel`).
    k_min, k_max : float
        Sector of the nonlinearity, ``k_min <= k_max``.
    n_grid : int, default 20000
        Number of log-spaced frequencies searched.

    Returns
    -------
    CircleResult
        Whether the sector is proved, and the largest ``k_max`` that would be.

    Raises
    ------
    ValueError
        If the sector is not finite and ordered, or `g` is not discrete-time.
    """
    if not (np.isfinite(k_min) and np.isfinite(k_max) and k_min <= k_max):
        raise ValueError(f"need finite k_min <= k_max, got [{k_min}, {k_max}]")
    if not g.isdtime(strict=True):
        raise ValueError("G must be a discrete-time system")
    ts = float(g.dt)
    t1 = control.feedback(g, k_min)
    _, stable, _, _ = classify_poles(t1.A)
    if not stable:
        return CircleResult(k_min, k_max, False, False, None, None)
    nyquist = np.pi / ts
    w = np.r_[0.0, np.geomspace(1e-6 * nyquist, nyquist, n_grid)]

    def minus_re(omega: np.ndarray) -> np.ndarray:
        resp = control.frequency_response(t1, np.atleast_1d(omega))
        return -np.asarray(resp.complex).reshape(-1).real

    values = minus_re(w)
    i = int(np.argmax(values))
    lo, hi = w[max(i - 1, 0)], w[min(i + 1, w.size - 1)]
    w_best, worst = w[i], float(values[i])
    if hi > lo:
        res = minimize_scalar(lambda x: -minus_re(x)[0], bounds=(lo, hi), method="bounded",
                              options={"xatol": 1e-9 * hi})
        if -res.fun > worst:
            w_best, worst = float(res.x), float(-res.fun)
    k_top = k_min + 1.0 / worst if worst > 0 else np.inf
    return CircleResult(k_min, k_max, bool(k_max < k_top), True, float(k_top),
                        float(w_best / (2 * np.pi)))


@dataclass(frozen=True, eq=False)
class StabilityReport:
    """What :func:`global_stability` found; ``verdict`` is the one line to print.

    Parameters
    ----------
    sectors : dict of Sector
        Measured on the trained sine (:func:`measure_sector`).
    loop_sector : Sector or None
        The channel's chord slopes seen in the experiment's runs, every case pooled (None if
        a run diverged).
    sector : Sector
        The sector the circle criterion is tested on: the hull of the channel's sector on the
        trained sine and ``loop_sector`` (every trajectory computed).
    sector_sources : tuple of str
        The trajectories ``sector`` covers, e.g. ``("trained sine (open loop)",
        "amplitude run (closed loop)")``.
    circle : CircleResult or None
        None when the criterion does not apply (``reason``).
    experiment : str
        Name of the experiment simulated (:func:`experiment_cases`).
    bounded : bool
        The experiment run stayed bounded.
    stop_time : float or None
        When the run diverged [s].
    verdict : {"proved stable", "not proved", "unstable"}
        The conclusion. "proved stable" is for a constant reference, and only for slopes
        inside ``sector``: a trajectory not among ``sector_sources`` may leave it.
    reason : str
        One line saying why.
    """

    sectors: dict
    loop_sector: Sector | None
    sector: Sector
    sector_sources: tuple
    circle: CircleResult | None
    experiment: str
    bounded: bool
    stop_time: float | None
    verdict: str
    reason: str

    def to_dict(self) -> dict:
        """The report as a JSON-safe dict."""
        return {"sectors": {k: v.to_dict() for k, v in self.sectors.items()},
                "loop_sector": None if self.loop_sector is None else self.loop_sector.to_dict(),
                "sector": self.sector.to_dict(), "sector_sources": list(self.sector_sources),
                "circle": None if self.circle is None else self.circle.to_dict(),
                "experiment": self.experiment, "bounded": self.bounded,
                "stop_time": self.stop_time, "verdict": self.verdict, "reason": self.reason}


def global_stability(loop: ControlLoop, experiment: str = "sine") -> StabilityReport:
    """Sectors, circle criterion and a simulation of ``experiment`` for one loop.

    The channel's slopes are measured on the trained sine (open loop) and in the experiment's
    closed-loop runs; the circle criterion is tested on the hull of both. Verdicts:
    ``unstable`` when the experiment's run diverges (shown, not inferred); ``proved stable``
    when the criterion proves the hull -- for a constant reference (the criterion is about
    increments), and only as long as the blocks' slopes stay inside the hull, which is
    measured on these trajectories, not established for all; otherwise ``not proved``.

    Parameters
    ----------
    loop : ControlLoop
        The loop.
    experiment : str, default "sine"
        Experiment to simulate (one of :data:`EXPERIMENTS`).

    Returns
    -------
    StabilityReport
        Sectors, circle-criterion result, simulation outcome and verdict.

    Raises
    ------
    ValueError
        If `experiment` is not an experiment.
    """
    sectors = measure_sector(loop)
    channel = sectors["channel"]
    result = run_experiment(experiment, loop)
    bounded = all(r.bounded for r in result.cases.values())
    stop = min((r.stop_time for r in result.cases.values() if not r.bounded), default=None)
    loop_sector, sources = None, ["trained sine (open loop)"]
    sector = channel
    if bounded:  # every case's increments, pooled
        loop_sector = hull([chord_sector(r.y, r.y_hat if loop.scheme == "direct" else r.s)
                             for r in result.cases.values()], channel.units)
        sector = hull([channel, loop_sector], channel.units)
        sources.append(f"{experiment} run (closed loop)")
    circle, why = None, ""
    try:
        circle = circle_criterion(sector_channel(loop), sector.k_min, sector.k_max)
    except ValueError as exc:
        why = str(exc)
    left = (loop_sector is not None
            and (loop_sector.k_min < channel.k_min or loop_sector.k_max > channel.k_max))
    note = (f"the {experiment} run's slopes {interval(loop_sector)} leave the trained sine's "
            f"{interval(channel)}, so their hull is tested; " if left else "")
    if not bounded:
        verdict = "unstable"
        reason = f"the {experiment} run diverged at t = {stop:.4g} s"
    elif circle is not None and circle.proved:
        verdict = "proved stable"
        reason = (f"{note}circle criterion: with a constant reference every increment decays "
                  f"for slopes in {interval(sector)} (measured on the "
                  f"{' and the '.join(sources)}), inside the proved [{sector.k_min:.4g}, "
                  f"{circle.k_max_proved:.4g}); sufficient only while the slopes stay in that "
                  f"sector, which other trajectories may leave")
    else:
        verdict = "not proved"
        if circle is None:
            reason = why
        elif not circle.base_stable:
            reason = (f"{note}the linear loop at the sector's lower bound {sector.k_min:.4g} "
                      f"is not asymptotically stable (condition 1)")
        else:
            reason = (f"{note}the sector's upper bound {sector.k_max:.4g} reaches beyond the "
                      f"{circle.k_max_proved:.4g} the criterion proves")
        reason += f"; the {experiment} run stayed bounded"
    return StabilityReport(sectors, loop_sector, sector, tuple(sources), circle, experiment,
                           bounded, stop, verdict, reason)
