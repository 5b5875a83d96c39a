"""A virtual sensor whose gain drifts: the test bench of online adaptation.

The gauges' gauge factor and the bridge's amplification age over a long run (sec. 3.5 of the
reference document: resistance settling, softening); :func:`with_gain_drift` models the part
that a fixed compensator cannot undo as a slow change of the sensor's gain. The drift is a
straight ramp of the recorded signal's gain from 1 at the first sample to ``1 + drift`` at the
last, applied to the sensor column (dR/R about the recording mean, so a pure gain).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..io import Recording
from ._virtual import VirtualSensor, fill_experiment_doc, simulate_experiment

__all__ = ["gain_ramp", "occasional_references", "simulate_drifting_experiment",
           "with_gain_drift"]


def gain_ramp(time: np.ndarray, drift: float) -> np.ndarray:
    """Gain at each time [s]: 1 at the first sample, ``1 + drift`` at the last, linear between.

    Parameters
    ----------
    time : numpy.ndarray, shape (n,)
        Sample times [s], advancing (n >= 2).
    drift : float
        Relative gain change over the run [-], above -1.

    Returns
    -------
    numpy.ndarray, shape (n,)
        The gain [-] at each sample.

    Raises
    ------
    ValueError
        If there are fewer than two samples, time does not advance, or `drift` is not a
        finite number above -1.
    """
    t = np.asarray(time, dtype=np.float64)
    if t.size < 2 or not t[-1] > t[0]:
        raise ValueError("a gain ramp needs at least two samples with advancing time")
    if not np.isfinite(drift) or drift <= -1.0:
        raise ValueError(f"drift {drift!r}: must be a finite number above -1 (a positive gain)")
    return 1.0 + drift * (t - t[0]) / (t[-1] - t[0])


def with_gain_drift(recording: Recording, drift: float = 0.10) -> Recording:
    """The recording with its sensor signal multiplied by :func:`gain_ramp`.

    Position and time are unchanged.

    Parameters
    ----------
    recording : Recording
        The recording.
    drift : float
        Relative gain change over the run [-] (0.1: the gain rises by 10 %).

    Returns
    -------
    Recording
        A copy with the drifting sensor signal; its source names the drift.
    """
    sensor = recording.sensor * gain_ramp(recording.time, drift)
    return dataclasses.replace(recording, sensor=sensor,
                               source=f"{recording.source}, gain drift {drift:+.0%}")


@fill_experiment_doc
def simulate_drifting_experiment(name: str, seed: int = 0, drift: float = 0.10,
                                 sensor: VirtualSensor | None = None) -> Recording:
    """:func:`~hystkit.sensors.simulate_experiment` with a sensor gain drift of ``drift``.

    Parameters
    ----------
    %(experiment)s
    drift : float
        Relative gain change over the run [-].
    sensor : VirtualSensor, optional
        The simulated sensor; the defaults when None.

    Returns
    -------
    Recording
        Time [s], position [mm] and the drifting sensor signal dR1/R1 - dR2/R2 [-] at the
        sensor's ``fs_out``.
    """
    return with_gain_drift(simulate_experiment(name, seed, sensor), drift)


def occasional_references(recording: Recording, every: float, seed: int = 0) -> np.ndarray:
    """The true position [mm] at one random sample in each ``every`` seconds, NaN elsewhere.

    What a bench gives an adapting stream now and then (a caliper reading, a camera frame, a
    known end stop). Random times within each interval: references at a fixed period would
    meet a periodic excitation at one phase, one position, and could not tell a gain from an
    offset.

    Parameters
    ----------
    recording : Recording
        A recording with a position column.
    every : float
        Interval holding one reference [s], at least one sample long.
    seed : int
        Seeds the random sample within each interval.

    Returns
    -------
    numpy.ndarray, shape (recording.n_samples,)
        The position [mm] at the chosen samples, NaN elsewhere.

    Raises
    ------
    ValueError
        If the recording has no position, or `every` is shorter than one sample.
    """
    if recording.position is None:
        raise ValueError(f"{recording.source}: no position column to take references from")
    n_every = round(every / recording.dt)
    if n_every < 1:
        raise ValueError(f"every {every!r} s: shorter than one sample ({recording.dt:g} s)")
    rng = np.random.default_rng(seed)
    starts = np.arange(0, recording.n_samples, n_every)
    picks = starts + rng.integers(0, n_every, starts.size)
    picks = picks[picks < recording.n_samples]
    reference = np.full(recording.n_samples, np.nan)
    reference[picks] = recording.position[picks]
    return reference
