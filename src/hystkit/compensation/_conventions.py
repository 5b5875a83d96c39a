"""Offsets, polarity and scales of a compensator: the same path for fitting and use data."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..io import Recording
from ._centring import DEFAULT_TARE_SECONDS, DEFAULT_TRACK_SECONDS, ORACLE_CENTER, sensor_level

__all__ = ["LinearBaseline", "Scaling", "centre_and_scale", "prepare_training_data"]


@dataclass(frozen=True)
class Scaling:
    """Offsets and scales of the fitting data (eq. 5.10), sensor units and mm."""

    sensor_offset: float
    sensor_scale: float
    position_offset: float
    position_scale: float


@dataclass(frozen=True)
class LinearBaseline:
    """Least-squares straight line position(sensor) in normalised units (MATLAB polyfit)."""

    slope: float
    intercept: float

    def __call__(self, s: np.ndarray) -> np.ndarray:
        return self.slope * s + self.intercept


def prepare_training_data(recordings: Sequence[Recording], center: str, *,
                          tare_seconds: float = DEFAULT_TARE_SECONDS,
                          track_seconds: float = DEFAULT_TRACK_SECONDS
                          ) -> tuple[dict, list[np.ndarray], list[np.ndarray]]:
    """Centre, orient and scale fitting recordings exactly as the compensator will at use.

    Returns
    -------
    conventions : dict
        ``scaling``, ``polarity``, ``sensor_reference``, ``rest_position`` for
        :class:`Compensator`.
    s, p : lists of arrays
        Normalised sensor and position per recording.
    """
    dt = recordings[0].dt
    levels = [sensor_level(center, r.sensor, dt, tare_seconds=tare_seconds,
                           track_seconds=track_seconds) for r in recordings]
    all_s = np.concatenate([r.sensor for r in recordings])
    all_p = np.concatenate([r.position for r in recordings])
    reference = 0.0
    if center == "tare":
        reference = float(np.mean([lv[-1] for lv in levels]))
    elif center == "track":
        reference = float(np.mean(all_s))
    if center in ("tare", "track"):
        adjusted = [r.sensor - lv + reference for r, lv in zip(recordings, levels, strict=True)]
    else:
        adjusted = [r.sensor for r in recordings]
    if center == ORACLE_CENTER:
        s_c = [a - np.mean(a) for a in adjusted]
        p_c = [r.position - np.mean(r.position) for r in recordings]
        s_off, p_off = float(np.mean(all_s)), float(np.mean(all_p))
    else:
        s_off = 0.0 if center == "none" else float(np.mean(np.concatenate(adjusted)))
        p_off = 0.0 if center == "none" else float(np.mean(all_p))
        s_c = [a - s_off for a in adjusted]
        p_c = [r.position - p_off for r in recordings]
    s_scale = float(np.max(np.abs(np.concatenate(s_c))))
    p_scale = float(np.max(np.abs(np.concatenate(p_c))))
    for scale, column in ((s_scale, "sensor"), (p_scale, "position")):
        if scale == 0:
            raise InputError(f"{recordings[0].source}: column '{column}' is constant; nothing "
                             f"to fit")
    corr = np.corrcoef(np.concatenate(s_c), np.concatenate(p_c))[0, 1]
    polarity = -1.0 if corr < 0 else 1.0
    n_tare = max(1, round(tare_seconds / dt))
    rest = float(np.mean([np.mean(r.position[:n_tare]) for r in recordings]))
    conventions = {"scaling": Scaling(s_off, s_scale, p_off, p_scale), "polarity": polarity,
                   "sensor_reference": reference,
                   "rest_position": rest if center == "tare" else None}
    return (conventions, [polarity * s / s_scale for s in s_c], [p / p_scale for p in p_c])


def centre_and_scale(recording: Recording, center: str) -> tuple[Scaling, np.ndarray,
                                                                 np.ndarray]:
    """One recording's scaling and its normalised sensor and position (eq. 5.10), centred
    by ``center`` as a fit would (compare and the benchmarks use it)."""
    conventions, s, p = prepare_training_data([recording], center)
    return conventions["scaling"], s[0], p[0]
