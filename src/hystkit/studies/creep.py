"""Creep check: a long step-and-hold experiment on the virtual sensor, compensated by the mPL and PL.

The document could not validate creep: "further experiments with longer excitation times are
required" (sec. 6). Here the virtual sensor holds three positions for a long time each (``+A``
from rest, ``-A``, then back to 0); compensators fitted on a standard excitation (the noise
experiment, 200 s) estimate the position throughout. During a hold the true position does not
move, so whatever the estimate does after the ramp is creep error.

The reference is the virtual sensor's own creep term: the strain of its conductive network
(:meth:`hystkit.sensors.VirtualSensor.network_strain`, noise-free, no temperature), whose
Prony part keeps moving after the imposed strain stops. Each creep number is relative to the
step the quantity made up to the start of the measurement, in %:

- ``physics_creep_pct``: network strain ``(m(t) - m(t_a)) / (m(t_a) - m_before)``;
- ``sensor_creep_pct``: the same for the recorded sensor signal dR1/R1 - dR2/R2;
- ``<model>_creep_error_pct``: the estimate's drift ``x_hat(t) - x_hat(t_a)`` in % of the true
  step (the true position is constant, so this is all error), also in mm.

``t_a`` is the start of the measurement, ``settle_seconds`` after the ramp (the 20 Hz filter
and the fastest Prony term have settled by then); every level is the mean over a 1 s window.
The virtual sensor's creep is exponential (Prony time constants up to 30 s by default), not
the log(t) creep of [15]: the output says how much of it is left after five of its slowest
time constants (``late_*``), which is the test of whether a long hold shows anything more.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass

import numpy as np

from ..compensation import fit_compensator
from ..sensors import VirtualSensor, simulate_experiment

__all__ = ["CREEP_COLUMNS", "CreepPlan", "creep_experiment", "creep_trajectory",
           "hold_levels"]

_WINDOW = 1.0  # s, every level is the mean over this window
_CHECKPOINTS = (1.0, 10.0, 100.0, 1000.0, 10000.0)  # s after t_a, while inside the hold

CREEP_COLUMNS = (("hold", "hold"), ("after_s", "t - t_a (s)"),
                 ("physics_creep_pct", "virtual sensor's creep term (%)"),
                 ("sensor_creep_pct", "sensor signal (%)"))


@dataclass(frozen=True)
class CreepPlan:
    """The step-and-hold trajectory.

    Parameters
    ----------
    hold_seconds : float
        Length of each of the three holds [s].
    amplitude_mm : float
        Held position A [mm]: holds at +A, -A, 0.
    ramp_seconds : float
        Duration of each ramp between holds [s].
    rest_seconds : float
        Rest at 0 before the first ramp [s].
    settle_seconds : float
        Wait after each ramp before the measurement starts [s].
    """

    hold_seconds: float = 1200.0
    amplitude_mm: float = 2.0
    ramp_seconds: float = 1.0
    rest_seconds: float = 10.0
    settle_seconds: float = 1.0

    def __post_init__(self) -> None:
        if not (self.ramp_seconds > 0 and self.settle_seconds >= 0 and self.amplitude_mm > 0):
            raise ValueError("ramp_seconds and amplitude_mm must be > 0, settle_seconds >= 0")
        if self.rest_seconds < _WINDOW:
            raise ValueError(f"rest_seconds must be at least {_WINDOW:g} s (the level window)")
        if self.hold_seconds < self.settle_seconds + 2 * _WINDOW + 1.0:
            raise ValueError(f"hold_seconds {self.hold_seconds:g} is too short: it needs the "
                             f"settling time, two {_WINDOW:g} s windows and 1 s of creep")


def creep_trajectory(plan: CreepPlan, fs: float) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """Time [s] and position [mm] at `fs` [Hz], and the holds.

    Each hold is a dict: ``level`` and ``before`` [mm], ``ramp_start``, ``ramp_end`` and
    ``end`` [s].

    Parameters
    ----------
    plan : CreepPlan
        The trajectory's timing and amplitude.
    fs : float
        Sample rate [Hz].

    Returns
    -------
    time : numpy.ndarray, shape (n,)
        Time [s] from 0 to the end of the last hold.
    position : numpy.ndarray, shape (n,)
        Position [mm]: rest at 0, then linear ramps to the held levels +A, -A, 0.
    holds : list of dict
        The three holds.
    """
    levels = (plan.amplitude_mm, -plan.amplitude_mm, 0.0)
    knots_t, knots_x, holds = [0.0, plan.rest_seconds], [0.0, 0.0], []
    before = 0.0
    for level in levels:
        start = knots_t[-1]
        ramp_end = start + plan.ramp_seconds
        end = ramp_end + plan.hold_seconds
        knots_t += [ramp_end, end]
        knots_x += [level, level]
        holds.append({"level": level, "before": before, "ramp_start": start,
                      "ramp_end": ramp_end, "end": end})
        before = level
    t = np.arange(round(knots_t[-1] * fs) + 1) / fs
    return t, np.interp(t, knots_t, knots_x), holds


def hold_levels(time: np.ndarray, y: np.ndarray, hold: dict, settle_seconds: float
                ) -> tuple[float, float, dict[float, float]]:
    """Levels of `y` around one hold: before the ramp, at ``t_a`` and at each checkpoint.

    Each level is the mean of `y` over a 1 s window. ``t_a`` is `settle_seconds` after the
    ramp's end (plus half a window); the checkpoints lie 1, 10, 100, ... s after it, while
    their window fits inside the hold; the last checkpoint is the hold's end.

    Parameters
    ----------
    time : numpy.ndarray, shape (n,)
        Time [s].
    y : numpy.ndarray, shape (n,)
        The signal.
    hold : dict
        One hold of :func:`creep_trajectory`.
    settle_seconds : float
        Wait after the ramp before ``t_a`` [s].

    Returns
    -------
    before : float
        Level in the window just before the ramp.
    at_a : float
        Level at ``t_a``.
    levels : dict of float to float
        ``{t - t_a [s]: level}`` at each checkpoint.
    """
    def level(centre: float) -> float:
        inside = np.abs(time - centre) <= _WINDOW / 2
        return float(np.mean(y[inside]))

    t_a = hold["ramp_end"] + settle_seconds + _WINDOW / 2
    last = hold["end"] - _WINDOW / 2
    after = [d for d in _CHECKPOINTS if t_a + d < last] + [last - t_a]
    return (level(hold["ramp_start"] - _WINDOW / 2), level(t_a),
            {d: level(t_a + d) for d in after})


def _relative(before: float, at_a: float, levels: dict[float, float]) -> dict[float, float]:
    """Each level's change since t_a in % of the step up to t_a."""
    return {d: 100.0 * (v - at_a) / (at_a - before) for d, v in levels.items()}


def creep_experiment(plan: CreepPlan = CreepPlan(), *, models: Sequence[str] = ("mpl", "pl"),
                     sizes: dict[str, int] | None = None, seed: int = 3, train_seed: int = 1,
                     train_excitation: str = "noise", sensor=None,
                     progress: Callable[[str], None] = lambda _: None) -> dict:
    """Run the hold experiment on the virtual sensor and measure each model's creep error.

    Parameters
    ----------
    plan : CreepPlan
    models : sequence of str
        Families fitted as direct compensators (deployable ``fit`` centring).
    sizes : dict, optional
        Family -> size (default: each family's ``default_size``).
    seed : int
        Seed of the hold recording (noise, temperature).
    train_seed, train_excitation
        The standard excitation the compensators are fitted on.
    sensor : hystkit.sensors.VirtualSensor, optional
        The sensor (default: ``VirtualSensor()``; the same for training and hold).
    progress : callable
        Receives one line per step.

    Returns
    -------
    dict
        ``settings``; ``sensor`` (Prony time constants and fractions); ``fits`` (status per
        model); ``rows``: per hold and checkpoint the creep of the network strain and of the
        sensor signal and each model's creep error (% of the step and mm); ``summary``: per
        hold the same at its end, and ``late_*``: what is left after five of the sensor's
        slowest Prony time constants.
    """
    sensor = VirtualSensor() if sensor is None else sensor
    t, x, holds = creep_trajectory(plan, sensor.fs_internal)
    progress(f"virtual sensor: 3 holds of {plan.hold_seconds:g} s at +-{plan.amplitude_mm:g} mm "
             f"and 0 ({t[-1] / 3600:.3g} h, {t.size} samples at {sensor.fs_internal:g} Hz)")
    recording = sensor.record(t, x, seed, source=f"<virtual sensor: creep holds, seed {seed}>")
    network = sensor.network_strain(sensor.strain_per_mm * x)
    train = simulate_experiment(train_excitation, train_seed, sensor)
    estimates, fits = {}, {}
    for name in models:
        progress(f"fitting {name} (direct, deployable centring) on {train.source}")
        comp = fit_compensator(train, (sizes or {}).get(name), model=name, diagnose=False)
        fits[name] = {"status": comp.fit_info["status"],
                      "status_message": comp.fit_info["status_message"],
                      "training_r2": comp.fit_info["training_r2"], "center": comp.center}
        estimates[name] = comp.estimate(recording)
    rows, summary = [], []
    late = 5.0 * max(sensor.prony_taus) if sensor.prony_taus else 0.0
    for hold in holds:
        label = f"{hold['before']:+g} -> {hold['level']:+g} mm"
        step = hold["level"] - hold["before"]
        physics = _relative(*hold_levels(t, network, hold, plan.settle_seconds))
        signal = _relative(*hold_levels(recording.time, recording.sensor, hold,
                                        plan.settle_seconds))
        drift = {}
        for name, est in estimates.items():
            _, at_a, levels = hold_levels(recording.time, est, hold, plan.settle_seconds)
            drift[name] = {d: v - at_a for d, v in levels.items()}
        for d in physics:
            row = {"hold": label, "after_s": d, "physics_creep_pct": physics[d],
                   "sensor_creep_pct": signal[d]}
            for name in estimates:
                row[f"{name}_creep_error_pct"] = 100.0 * drift[name][d] / step
                row[f"{name}_creep_error_mm"] = drift[name][d]
            rows.append(row)
        summary.append({**rows[-1], "step_mm": step,
                        **_late_creep(t, network, recording, estimates, hold, plan, late, step)})
    return {"settings": {**asdict(plan), "models": list(models), "sizes": dict(sizes or {}),
                         "seed": seed, "train_seed": train_seed,
                         "train_excitation": train_excitation},
            "sensor": {"prony_taus_s": list(sensor.prony_taus),
                       "prony_fractions": list(sensor.prony_fractions),
                       "late_after_s": late},
            "fits": fits, "rows": rows, "summary": summary}


def _late_creep(t: np.ndarray, network: np.ndarray, recording, estimates: dict, hold: dict,
                plan: CreepPlan, late: float, step: float) -> dict:
    """Creep between ``t_a + late`` and the hold's end, in % of the step up to ``t_a``: what a
    long hold adds beyond five of the sensor's slowest time constants (None if the hold is
    shorter than that)."""
    t_a = hold["ramp_end"] + plan.settle_seconds + _WINDOW / 2
    if t_a + late >= hold["end"] - _WINDOW:
        return {"late_physics_creep_pct": None, "late_sensor_creep_pct": None,
                **{f"late_{name}_creep_error_pct": None for name in estimates}}
    late_hold = {**hold, "ramp_end": hold["ramp_end"] + late}

    def change(time: np.ndarray, y: np.ndarray) -> tuple[float, float]:
        """(change from t_a + late to the end, step up to t_a)"""
        before, at_a, _ = hold_levels(time, y, hold, plan.settle_seconds)
        _, at_late, levels = hold_levels(time, y, late_hold, plan.settle_seconds)
        return levels[max(levels)] - at_late, at_a - before

    out = {}
    for key, (time, y) in (("physics", (t, network)),
                           ("sensor", (recording.time, recording.sensor))):
        moved, made = change(time, y)
        out[f"late_{key}_creep_pct"] = 100.0 * moved / made
    for name, est in estimates.items():
        moved, _ = change(recording.time, est)
        out[f"late_{name}_creep_error_pct"] = 100.0 * moved / step
    return out
