"""Raw mode of the virtual sensor: what the oscilloscope would have saved.

The :class:`~hystkit.sensors.VirtualSensor` runs at its internal rate (400 Hz) for the whole
experiment; its position and gauge resistances are then evaluated at the scope rate with a
cubic spline (the trajectories have no content above 4 Hz and the resistance noise is a
400 Hz-sampled process, so the spline adds nothing the decimation would keep). From them:

* ``v1``, ``v2``: the half-bridge voltages across the bridge resistor (eq. 4.2) plus white
  scope noise;
* ``encoder``: the merged A/B signal of sec. 4.2.1. The hex buffer drives A through
  R_d1 = 1 kOhm and B through R_d2 = 2 kOhm into one node loaded by the scope, which gives the
  four levels of ``(2A + B)/3`` of the logic swing, slightly unequal because of the buffer's
  output resistance and logic-low voltage; the logic supply drifts slowly, edges have a finite
  time constant (samples caught mid-edge), and there is white noise. ``enc_a``/``enc_b`` instead
  give the two logic channels.
* ``v0`` (optional, ``supply_channel``): the bridge supply as a fourth scope channel measures it
  (the reference channel of sec. 4.2.1), with the same white scope noise. The bridge supply can
  drift (``bridge_supply_drift``, a slow sine; 0 by default, so the bridge sees exactly V0);
  the drift then enters v1, v2 through eq. 4.2 and only the v0 channel can remove it.

The file is written chunk by chunk (blocks of 2**20 samples, each with its own noise seed), so
memory does not grow with the recording and the file does not depend on any chunk size. A
settings file with the same stem (``.toml``) records R_br, V0, fs and the sample count, so
``hystkit preprocess`` needs no options. Faults can be injected to test the decoder: missed
encoder states (each an illegal double transition) and one-sample spikes.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from ..io import RawWriter, Recording, check_output_path, write_raw_config
from ..preprocess import DEFAULT_STATES, downsample, lowpass_zero_phase
from ..signals import EXPERIMENTS, excitation
from ._scope import ScopeSettings, scope_block, spline_at
from ._virtual import VirtualSensor

__all__ = ["RawTruth", "simulate_raw", "with_asymmetry"]

_BLOCK = 1 << 20  # samples per written block and per noise seed


def with_asymmetry(sensor: VirtualSensor, asymmetry: float | None = None,
                   age_hours: float | None = None) -> VirtualSensor:
    """`sensor` with another gauge symmetry and/or another time since printing (sec. 3.5.1).

    Parameters
    ----------
    sensor : VirtualSensor
        The sensor.
    asymmetry : float, optional
        Gauge symmetry ``2 (R1 - R2)/(R1 + R2)`` of the base resistances [-], in (-2, 2);
        their mean is kept.
    age_hours : float, optional
        Time since printing [h], >= 0.

    Returns
    -------
    VirtualSensor
        A copy with the given values; unchanged where an argument is None.

    Raises
    ------
    ValueError
        If `asymmetry` is outside (-2, 2) or `age_hours` is negative.
    """
    if asymmetry is not None:
        if not -2 < asymmetry < 2:
            raise ValueError(f"asymmetry must lie in (-2, 2), got {asymmetry}")
        mean = 0.5 * sum(sensor.base_resistance)
        sensor = replace(sensor, base_resistance=(mean * (1 + asymmetry / 2),
                                                  mean * (1 - asymmetry / 2)))
    if age_hours is not None:
        if age_hours < 0:
            raise ValueError(f"age_hours must be >= 0, got {age_hours}")
        sensor = replace(sensor, age_hours=age_hours)
    return sensor


@dataclass(frozen=True, eq=False)
class RawTruth:
    """What the raw file encodes, at the sensor's internal rate.

    Parameters
    ----------
    time : numpy.ndarray, shape (n,)
        Time [s].
    position : numpy.ndarray, shape (n,)
        Position [mm].
    resistance : numpy.ndarray, shape (2, n)
        Resistances of gauges R1, R2 before scope noise [Ohm].
    fs_internal : float
        The sensor's internal rate [Hz].
    count0 : int
        The encoder count at the first sample.
    encoder_mm : float
        Encoder resolution [mm per count].
    n_samples : int
        Samples per channel of the raw file.
    fs : float
        Sample rate of the raw file [Hz].
    missed : numpy.ndarray, shape (k, 2)
        (time [s], hidden count) of each injected missed state.
    spikes : numpy.ndarray of int
        Raw sample indices of the injected spikes.
    """

    time: np.ndarray
    position: np.ndarray
    resistance: np.ndarray
    fs_internal: float
    count0: int
    encoder_mm: float
    n_samples: int
    fs: float
    missed: np.ndarray
    spikes: np.ndarray

    def counts(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """True encoder counts relative to the first sample, for raw samples start..stop-1."""
        stop = self.n_samples if stop is None else stop
        x = spline_at(self._coefficients(self.position[np.newaxis]), self.fs_internal,
                       np.arange(start, stop) / self.fs)[0]
        return np.round(x / self.encoder_mm).astype(np.int64) - self.count0

    def recording(self, cutoff: float = 20.0, fs_out: float = 40.0) -> Recording:
        """The truth through the document's chain (eq. 4.1, 4.4-4.5) at `fs_out`: exact
        position [mm] relative to the start and dR1/R1 - dR2/R2, as preprocessing should give."""
        t, position, dr1, dr2 = self._filtered(cutoff, fs_out)
        return Recording(time=t, position=position, sensor=dr1 - dr2, source="<raw truth>")

    def gauge_changes(self, cutoff: float = 20.0, fs_out: float = 40.0) -> dict[str, np.ndarray]:
        """dR/R of each gauge (``dr1``, ``dr2`` [-], eq. 4.4-4.5) on the grid of
        :meth:`recording`: what preprocessing should give in its ``dr1``, ``dr2`` columns."""
        _, _, dr1, dr2 = self._filtered(cutoff, fs_out)
        return {"dr1": dr1, "dr2": dr2}

    def _filtered(self, cutoff: float, fs_out: float) -> tuple[np.ndarray, ...]:
        rows = np.vstack([self.position - self.count0 * self.encoder_mm, self.resistance])
        filtered = lowpass_zero_phase(rows, self.fs_internal, cutoff)
        position, r1, r2 = downsample(filtered, self.fs_internal, fs_out)
        t = downsample(self.time, self.fs_internal, fs_out)
        return t, position, (r1 - r1.mean()) / r1.mean(), (r2 - r2.mean()) / r2.mean()

    def _coefficients(self, rows: np.ndarray) -> np.ndarray:
        return np.stack([CubicSpline(self.time, r).c for r in rows])


def simulate_raw(path: str | os.PathLike[str], name: str, seed: int = 0, *,
                 sensor: VirtualSensor | None = None, scope: ScopeSettings | None = None,
                 duration: float | None = None, force: bool = False) -> RawTruth:
    """Write the raw scope recording of experiment `name` on the virtual sensor.

    Parameters
    ----------
    path : str or path-like
        ``.csv`` or ``.parquet``; the settings go to the same stem with ``.toml``.
    name : str
        Excitation (sine, decay, chirp, noise).
    seed : int
        Seeds the sensor (as :func:`simulate_experiment`) and the scope noise.
    sensor, scope : optional
        Virtual sensor and instrument settings (defaults when None).
    duration : float, optional
        Keep only the first `duration` seconds of the experiment.
    force : bool
        Overwrite existing files.

    Returns
    -------
    RawTruth
    """
    sensor = VirtualSensor() if sensor is None else sensor
    scope = ScopeSettings() if scope is None else scope
    path = Path(path)
    config_path = path.with_suffix(".toml")
    for p in (path, config_path):
        check_output_path(p, force)
    t, x = excitation(name, sensor.fs_internal, seed)
    if duration is not None:
        if not 0 < duration:
            raise ValueError(f"duration must be positive, got {duration}")
        keep = t <= duration + 1e-12
        t, x = t[keep], x[keep]
    if t.size < 8:
        raise ValueError("duration too short: fewer than 8 internal samples")
    rng = np.random.default_rng(seed)
    r = sensor.resistances(x, t, rng)  # same draws as VirtualSensor.record for this seed
    n = int(np.floor(t[-1] * scope.fs + 1e-9)) + 1
    coef = np.stack([CubicSpline(t, row).c for row in (x, r[0], r[1])])
    step = sensor.encoder_mm
    count0 = int(np.round(x[0] / step))
    fault_rng = np.random.default_rng([seed, 0xFA17])
    missed = _choose_missed(t, x, step, scope.n_missed_states, fault_rng)
    # Spikes after the first 1 % of samples, so the first sample (it sets the state) is clean.
    spikes = np.sort(n // 100 + fault_rng.choice(n - n // 100, scope.n_spikes, replace=False)) \
        if scope.n_spikes else np.zeros(0, dtype=np.int64)
    columns = ("time", "v1", "v2") + (("encoder",) if scope.encoder_mode == "merged"
                                      else ("enc_a", "enc_b")) + ("v0",) * scope.supply_channel
    edge_state = np.zeros(1 if scope.encoder_mode == "merged" else 2) + np.nan
    a_edge = np.exp(-1.0 / (scope.fs * scope.edge_tau)) if scope.edge_tau > 0 else 0.0
    um = sensor.encoder_mm * 1e3
    config = {"r_bridge": scope.r_bridge, "v_supply": scope.v_supply, "fs": scope.fs,
              "n_samples": n, "um_per_count": um}
    if scope.encoder_mode == "merged":
        config["encoder_states"] = [format(q, "02b") for q in DEFAULT_STATES]
    if scope.supply_channel:
        config["supply_channel"] = True
    notes = {"excitation": name, "seed": seed, "duration_s": float(t[-1]),
             "bridge_noise_v": scope.bridge_noise_v, "encoder_noise_v": scope.encoder_noise_v,
             "edge_tau_s": scope.edge_tau, "supply_drift": scope.supply_drift,
             "bridge_supply_drift": scope.bridge_supply_drift,
             "bridge_drift_period_s": scope.bridge_drift_period,
             "missed_states": len(missed), "spikes": int(spikes.size),
             "age_hours": sensor.age_hours,
             "base_resistance_ohm": [float(v) for v in sensor.base_resistance]}
    comment = (f"hystkit raw recording: virtual sensor, {EXPERIMENTS[name].description}\n"
               f"read by 'hystkit preprocess {path.name}'")
    # Data and settings appear together or not at all: the settings are published last inside
    # the data's block and removed again if the data then fail to publish.
    settings_written = False
    try:
        with RawWriter(path, columns, force=force) as writer:
            for b, start in enumerate(range(0, n, _BLOCK)):
                ts = np.arange(start, min(n, start + _BLOCK)) / scope.fs
                writer.write(**scope_block(ts, start, np.random.default_rng([seed, 0x5C0E, b]),
                                          coef, sensor, scope, missed, spikes, columns,
                                          edge_state, a_edge))
            write_raw_config(config_path, {**config, "simulation": notes}, comment=comment,
                             force=force)
            settings_written = True
    except BaseException:
        if settings_written:
            config_path.unlink(missing_ok=True)
        raise
    return RawTruth(time=t, position=x, resistance=r, fs_internal=sensor.fs_internal,
                    count0=count0, encoder_mm=step, n_samples=n, fs=scope.fs,
                    missed=np.array([(m[0], m[1]) for m in missed]).reshape(-1, 2),
                    spikes=spikes)


def _choose_missed(t: np.ndarray, x: np.ndarray, step: float, n_missed: int,
                   rng: np.random.Generator) -> list[tuple[float, int, int]]:
    """Internal steps in which the position moves monotonically over >= 3 counts; in each, the
    first count passed is hidden. Returns (centre time [s], hidden count, direction)."""
    if n_missed == 0:
        return []
    counts = np.round(x / step).astype(np.int64)
    dx = np.diff(counts)
    velocity = np.gradient(x)
    ok = (np.abs(dx) >= 3) & (np.sign(velocity[:-1]) == np.sign(dx)) \
        & (np.sign(velocity[1:]) == np.sign(dx))
    candidates = np.flatnonzero(ok)[2:]
    if candidates.size < n_missed:
        raise ValueError(f"cannot inject {n_missed} missed states: only {candidates.size} "
                         "places move fast enough (use a longer or faster excitation)")
    chosen = np.sort(rng.choice(candidates, n_missed, replace=False))
    return [(0.5 * (t[i] + t[i + 1]), int(counts[i] + np.sign(dx[i])), int(np.sign(dx[i])))
            for i in chosen]


