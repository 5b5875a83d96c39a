"""The document's closed-loop experiments (sec. 7.2-7.3) as reusable case lists.

Each experiment is a list of :class:`Case` (reference, optional output disturbance); a sweep has
several. :func:`run_experiment` runs every case through one :class:`ControlLoop` and
collects the responses and their metrics.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, replace

import numpy as np

from ._blocks import (
    DOCUMENT_PID_DIRECT,
    DOCUMENT_PID_WEIGHTING,
    PID,
    TS,
    DisturbanceObserver,
    Plant,
)
from ._loop import ControlLoop, tare
from ._names import EXPERIMENTS
from ._noise import NoiseSpec
from ._sensor_blocks import SensorModels
from ._simulate import LoopResponse, simulate_loop

__all__ = [
    "AMPLITUDES_MM",
    "EXPERIMENTS",
    "FREQUENCIES_HZ",
    "Case",
    "ExperimentResult",
    "build_loop",
    "cubic_trajectory",
    "experiment_cases",
    "measured_sensor_noise",
    "noise_study",
    "run_experiment",
    "sine_reference",
]

FREQUENCIES_HZ = (0.125, 0.25, 0.5, 1.0, 2.0)
"""Frequency sweep at 3 mm (fig. 7.6, 7.13); 0.5 Hz is the trained excitation."""
AMPLITUDES_MM = (1.0, 2.0, 3.0, 4.5, 6.0)
"""Amplitude sweep at 0.5 Hz (fig. 7.7, 7.12); 3 mm is the trained excitation."""
TRAINED = (0.5, 3.0)  # Hz, mm: the compensator's and S_m's training sine (sec. 7.2)


@dataclass(frozen=True, eq=False)
class Case:
    """One run: reference ``r`` [m] at ``Ts``, optional output disturbance ``d_out`` [m].

    Parameters
    ----------
    label : str
        Name of the case (key of :attr:`ExperimentResult.cases`).
    r : numpy.ndarray, shape (n,)
        Reference position [m], one value per sample.
    d_out : numpy.ndarray, shape (n,), optional
        Output disturbance [m] added to the plant position.
    description : str, default ""
        One line saying what the case is.
    """

    label: str
    r: np.ndarray
    d_out: np.ndarray | None = None
    description: str = ""


def sine_reference(n_steps: int, ts: float = TS, amplitude: float = 3e-3,
                   frequency: float = 0.5) -> np.ndarray:
    """``amplitude sin(2 pi f t)`` [m]; the defaults are eq. 7.3, ``0.003 sin(pi t)``.

    Parameters
    ----------
    n_steps : int
        Number of samples.
    ts : float, default TS
        Sample time [s]; the first sample is at ``t = 0``.
    amplitude : float, default 3e-3
        Amplitude [m].
    frequency : float, default 0.5
        Frequency [Hz].

    Returns
    -------
    numpy.ndarray, shape (n_steps,)
        Reference position [m].
    """
    return amplitude * np.sin(2 * np.pi * frequency * np.arange(n_steps) * ts)


def cubic_trajectory(waypoints_mm: tuple[float, ...] = (0.0, 3.0, -3.0, 1.5, -1.5, 0.0), *,
                     v_max: float = 7.5e-3, a_max: float = 0.15, dwell: float = 0.5,
                     ts: float = TS) -> np.ndarray:
    """Rest-to-rest cubic segments through waypoints within velocity and acceleration bounds.

    Each move of ``D`` [m] is ``p(s) = p0 + D (3 s^2 - 2 s^3)``, ``s = t / T`` (the cubic
    polynomial trajectory of MATLAB's ``cubicpolytraj`` with zero end velocities): constant jerk
    per segment, so eq. 7.9's integration of jerk, acceleration and velocity gives it exactly.
    Peak speed ``1.5 |D| / T`` and peak acceleration ``6 |D| / T^2`` set the shortest ``T``
    within ``v_max`` [m/s] and ``a_max`` [m/s^2] (sec. 7.3.1: 7.5 mm/s, 0.15 m/s^2), rounded
    up to whole samples; the plant dwells ``dwell`` seconds at every waypoint.

    Parameters
    ----------
    waypoints_mm : tuple of float
        Positions to visit [mm], the first one is the start.
    v_max : float, default 7.5e-3
        Velocity bound [m/s].
    a_max : float, default 0.15
        Acceleration bound [m/s^2].
    dwell : float, default 0.5
        Time at rest at every waypoint, the first included [s].
    ts : float, default TS
        Sample time [s].

    Returns
    -------
    r : array
        Position [m] every ``ts``.
    """
    pieces = [np.full(round(dwell / ts), waypoints_mm[0] * 1e-3)]
    for a, b in itertools.pairwise(waypoints_mm):
        d = (b - a) * 1e-3
        duration = max(1.5 * abs(d) / v_max, np.sqrt(6 * abs(d) / a_max))
        n = int(np.ceil(duration / ts))
        s = np.arange(n) / n
        pieces.append(a * 1e-3 + d * (3 * s ** 2 - 2 * s ** 3))
        pieces.append(np.full(round(dwell / ts), b * 1e-3))
    return np.concatenate(pieces)


def _steps(seconds: float, ts: float) -> int:
    return round(seconds / ts)


def experiment_cases(name: str, ts: float = TS) -> list[Case]:
    """The cases of experiment ``name`` (one of :data:`EXPERIMENTS`).

    - ``sine``: eq. 7.3 for 5 periods (10 s), fig. 7.5 / 7.10;
    - ``frequency``: :data:`FREQUENCIES_HZ` at 3 mm, ``max(10 s, 5 periods)`` each;
    - ``amplitude``: :data:`AMPLITUDES_MM` at 0.5 Hz, 10 s each;
    - ``cubic``: :func:`cubic_trajectory` (sec. 7.3.1);
    - ``disturbance``: the eq. 7.3 sine for 5 s with an output step of 0 (baseline), 1 and
      3 mm from 1.7 s to 2.2 s (sec. 7.3.2; the document does not state its reference there).

    Parameters
    ----------
    name : str
        One of :data:`EXPERIMENTS`.
    ts : float, default TS
        Sample time [s] of the references.

    Returns
    -------
    list of Case
        The experiment's runs, in order.

    Raises
    ------
    ValueError
        If `name` is not an experiment.
    """
    if name == "sine":
        return [Case("sine", sine_reference(_steps(10.0, ts), ts),
                     description="3 mm sin(pi t), eq. 7.3")]
    if name == "frequency":
        return [Case(f"{f:g} Hz", sine_reference(_steps(max(10.0, 5 / f), ts), ts, 3e-3, f),
                     description=f"3 mm, {f:g} Hz" + (" (trained)" if f == TRAINED[0] else ""))
                for f in FREQUENCIES_HZ]
    if name == "amplitude":
        return [Case(f"{a:g} mm", sine_reference(_steps(10.0, ts), ts, a * 1e-3, 0.5),
                     description=f"{a:g} mm, 0.5 Hz" + (" (trained)" if a == TRAINED[1] else ""))
                for a in AMPLITUDES_MM]
    if name == "cubic":
        return [Case("cubic", cubic_trajectory(ts=ts),
                     description="cubic segments 0, 3, -3, 1.5, -1.5, 0 mm; |v| <= 7.5 mm/s, "
                                 "|a| <= 0.15 m/s^2")]
    if name == "disturbance":
        r = sine_reference(_steps(5.0, ts), ts)
        t = np.arange(r.size) * ts
        window = (t >= 1.7) & (t < 2.2)
        return [Case(f"{a:g} mm step", r, np.where(window, a * 1e-3, 0.0),
                     description=f"output disturbance {a:g} mm, 1.7-2.2 s")
                for a in (0.0, 1.0, 3.0)]
    raise ValueError(f"unknown experiment {name!r}; choose one of {EXPERIMENTS}")


def build_loop(scheme: str, models: SensorModels, *, pid: PID | None = None,
               plant: Plant | None = None, dob: DisturbanceObserver | None = None,
               zero_at_start: bool = True, ts: float = TS) -> ControlLoop:
    """A loop of scheme ``direct`` or ``weighting`` from fitted models, document gains default.

    Parameters
    ----------
    scheme : {"direct", "weighting"}
        Loop scheme (fig. 7.1 or fig. 7.8).
    models : SensorModels
        Sensor ``S_r``, compensator, ``S_m`` and sensor gain of the loop.
    pid : PID, optional
        Controller; default :data:`DOCUMENT_PID_DIRECT` or :data:`DOCUMENT_PID_WEIGHTING`.
    plant : Plant, optional
        Plant; default :class:`Plant` ().
    dob : DisturbanceObserver, optional
        Disturbance observer; default none.
    zero_at_start : bool, default True
        Apply :func:`tare` (estimates zeroed on the sensor's rest reading at ``y = 0``).
    ts : float, default TS
        Sample time [s].

    Returns
    -------
    ControlLoop
        The assembled loop.
    """
    if pid is None:
        pid = DOCUMENT_PID_DIRECT if scheme == "direct" else DOCUMENT_PID_WEIGHTING
    loop = ControlLoop(scheme, models.sensor, pid, plant or Plant(),
                       compensator=models.compensator, model=models.model,
                       sensor_gain=models.sensor_gain, dob=dob, ts=ts)
    return tare(loop) if zero_at_start else loop


@dataclass(frozen=True, eq=False)
class ExperimentResult:
    """Responses of every case of one experiment on one loop.

    Parameters
    ----------
    name : str
        Experiment name (one of :data:`EXPERIMENTS`).
    loop : ControlLoop
        The loop every case ran on.
    cases : dict of str to LoopResponse
        Response of each case, by label.
    descriptions : dict of str to str
        Description of each case, by label.
    seconds : float
        Wall time of the whole experiment [s].
    noise : NoiseSpec, optional
        Noise the cases ran with; None for none.
    """

    name: str
    loop: ControlLoop
    cases: dict[str, LoopResponse]
    descriptions: dict[str, str]
    seconds: float
    noise: NoiseSpec | None = None

    def metrics(self) -> dict:
        """``{"experiment", "scheme", "cases": {label: metrics}}``; a single-case experiment
        also carries its metrics at the top level.

        Disturbance cases add ``e_p_max_during`` (max ``|r - y|`` over 2.0-2.2 s, the step's
        last 0.2 s) and ``e_p_max_after`` (from 2.5 s on): the step itself makes ``e_p_max`` at
        least its height, so these show the rejection and the recovery.
        """
        cases = {}
        for k, v in self.cases.items():
            cases[k] = {"description": self.descriptions[k], **v.metrics()}
            if self.name == "disturbance":
                e_p = np.abs(v.plant_error)
                for key, (a, b) in (("e_p_max_during", (2.0, 2.2)),
                                    ("e_p_max_after", (2.5, np.inf))):
                    sel = e_p[(v.t >= a) & (v.t < b)]
                    cases[k][key] = float(sel.max()) if sel.size else None
        out = {"experiment": self.name, "scheme": self.loop.scheme,
               "dob": self.loop.dob is not None, "cases": cases,
               "noise": None if self.noise is None else self.noise.to_dict(),
               "all_bounded": all(v.bounded for v in self.cases.values()),
               "seconds": sum(v.seconds for v in self.cases.values())}
        if len(self.cases) == 1:
            out.update(next(iter(self.cases.values())).metrics())
        return out


def run_experiment(name: str, loop: ControlLoop,
                   noise: NoiseSpec | None = None) -> ExperimentResult:
    """Run every case of experiment ``name`` from rest; see :func:`experiment_cases`.

    Parameters
    ----------
    name : str
        One of :data:`EXPERIMENTS`.
    loop : ControlLoop
        The loop to run.
    noise : NoiseSpec, optional
        Sensor and process noise, case ``k`` drawn by ``noise.draw(n, k)``; None runs without.

    Returns
    -------
    ExperimentResult
        Every case's response and the total wall time.

    Raises
    ------
    ValueError
        If `name` is not an experiment.
    """
    t0 = time.perf_counter()
    cases, descriptions = {}, {}
    for k, case in enumerate(experiment_cases(name, loop.ts)):
        sensor, process = (None, None) if noise is None else noise.draw(case.r.size, k)
        cases[case.label] = simulate_loop(loop, case.r, d_out=case.d_out, d_in=process,
                                          noise=sensor)
        descriptions[case.label] = case.description
    return ExperimentResult(name, loop, cases, descriptions, time.perf_counter() - t0, noise)


def measured_sensor_noise(loop: ControlLoop, response: LoopResponse) -> float:
    """SD of the noise in the loop's sensor signal [sensor units].

    The noise is ``s`` minus ``S_r`` run open loop on the plant position the run recorded
    (the same state from rest).

    Parameters
    ----------
    loop : ControlLoop
        The loop the run used (its sensor ``S_r`` and sample time).
    response : LoopResponse
        The run, started from rest.

    Returns
    -------
    float
        Standard deviation of ``s - S_r(y)`` [sensor units].
    """
    clean, _ = loop.sensor.simulate(response.y, loop.ts)
    return float(np.std(response.s - clean))


def noise_study(name: str, loop: ControlLoop, noise: NoiseSpec,
                dob: DisturbanceObserver) -> list[dict]:
    """Experiment ``name`` without and with ``noise``, each without and with ``dob``.

    Parameters
    ----------
    name : str
        One of :data:`EXPERIMENTS`.
    loop : ControlLoop
        The loop (its own DOB is replaced by none, then by `dob`).
    noise : NoiseSpec
        Noise of the noisy runs.
    dob : DisturbanceObserver
        Observer of the runs with a DOB.

    Returns
    -------
    rows : list of dict
        One per (noise, DOB, case): ``noise`` and ``dob`` flags, ``case``, ``e_p_rms``,
        ``e_p_max`` [m], ``u_rms`` [N] (control effort), ``sensor_noise_sd`` measured in the
        run's sensor signal [sensor units] and ``bounded``.
    """
    rows = []
    for with_noise in (False, True):
        for observer in (None, dob):
            result = run_experiment(name, replace(loop, dob=observer),
                                    noise if with_noise else None)
            for label, resp in result.cases.items():
                m = resp.metrics()
                rows.append({"noise": with_noise, "dob": observer is not None, "case": label,
                             "e_p_rms": m.get("e_p_rms"), "e_p_max": m.get("e_p_max"),
                             "u_rms": float(np.sqrt(np.mean(resp.u ** 2))) if resp.u.size
                             else None,
                             "sensor_noise_sd": measured_sensor_noise(loop, resp)
                             if resp.bounded else None,
                             "bounded": resp.bounded})
    return rows
