"""Offsets, polarity and scales of a compensator: the same path for fitting and use data."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..io import Recording
from ._centring import DEFAULT_TARE_SECONDS, DEFAULT_TRACK_SECONDS, ORACLE_CENTER, sensor_level

__all__ = ["LinearBaseline", "Scaling", "centre_and_scale", "prepare_training_data"]

_CHUNK = 65_536  # samples per chunk of the straight line's sums


@dataclass(frozen=True)
class Scaling:
    """Offsets and scales of the fitting data (eq. 5.10), sensor units and mm.

    Parameters
    ----------
    sensor_offset, sensor_scale : float
        Offset and scale [sensor units] of the sensor.
    position_offset, position_scale : float
        Offset and scale [mm] of the position.
    """

    sensor_offset: float
    sensor_scale: float
    position_offset: float
    position_scale: float


@dataclass(frozen=True)
class LinearBaseline:
    """Least-squares straight line position(sensor) in normalised units (MATLAB polyfit).

    Parameters
    ----------
    slope, intercept : float
        The line ``p = slope * s + intercept`` in normalised units.
    """

    slope: float
    intercept: float

    def __call__(self, s: np.ndarray) -> np.ndarray:
        return self.slope * s + self.intercept

    @classmethod
    def fit(cls, s: np.ndarray, p: np.ndarray) -> LinearBaseline:
        """Least-squares line through ``(s, p)`` (``np.polyfit(s, p, 1)`` to rounding), from
        centred sums taken chunk by chunk: no ``n x 2`` design matrix and its copies."""
        s_mean, p_mean = float(np.mean(s)), float(np.mean(p))
        sxy = sxx = 0.0
        for start in range(0, s.size, _CHUNK):
            ds = s[start:start + _CHUNK] - s_mean
            sxy += float(ds @ (p[start:start + _CHUNK] - p_mean))
            sxx += float(ds @ ds)
        slope = sxy / sxx
        return cls(slope, p_mean - slope * s_mean)


def prepare_training_data(recordings: Sequence[Recording], center: str, *,
                          tare_seconds: float = DEFAULT_TARE_SECONDS,
                          track_seconds: float = DEFAULT_TRACK_SECONDS
                          ) -> tuple[dict, list[np.ndarray], list[np.ndarray]]:
    """Centre, orient and scale fitting recordings exactly as the compensator will at use.

    Parameters
    ----------
    recordings : sequence of Recording
        Fitting recordings with position and sensor, one rate.
    center : {"fit", "tare", "track", "recording", "none"}
        Centring mode.
    tare_seconds, track_seconds : float, default 2.0 and 100.0
        Tare window and drift-tracker time constant [s].

    Returns
    -------
    conventions : dict
        ``scaling``, ``polarity``, ``sensor_reference``, ``rest_position`` for
        :class:`Compensator`.
    s, p : lists of arrays
        Normalised sensor and position per recording.

    Raises
    ------
    InputError
        A constant position or sensor column (naming the first file).
    """
    dt = recordings[0].dt
    levels = [sensor_level(center, r.sensor, dt, tare_seconds=tare_seconds,
                           track_seconds=track_seconds) for r in recordings]
    # Whole-data statistics by sums over recordings and columns worked on in place: no
    # concatenated copy and no full-length temporary (memory of `hystkit fit`, issue 10).
    n_all = sum(r.sensor.size for r in recordings)
    mean_s = _total(r.sensor for r in recordings) / n_all
    mean_p = _total(r.position for r in recordings) / n_all
    reference = 0.0
    if center == "tare":
        reference = float(np.mean([lv[-1] for lv in levels]))
    elif center == "track":
        reference = mean_s
    if center in ("tare", "track"):
        s_c = [_shifted(r.sensor - lv, -reference) for r, lv in zip(recordings, levels,
                                                                   strict=True)]
    else:
        s_c = [np.array(r.sensor, dtype=float) for r in recordings]
    if center == ORACLE_CENTER:
        s_c = [_shifted(a, np.mean(a)) for a in s_c]
        p_c = [_shifted(np.array(r.position, dtype=float), np.mean(r.position))
               for r in recordings]
        s_off, p_off = mean_s, mean_p
    else:
        s_off = 0.0 if center == "none" else _total(s_c) / n_all
        p_off = 0.0 if center == "none" else mean_p
        s_c = [_shifted(a, s_off) for a in s_c]
        p_c = [_shifted(np.array(r.position, dtype=float), p_off) for r in recordings]
    s_scale, p_scale = _max_abs(s_c), _max_abs(p_c)
    for scale, column in ((s_scale, "sensor"), (p_scale, "position")):
        if scale == 0:
            raise InputError(f"{recordings[0].source}: column '{column}' is constant; nothing "
                             f"to fit")
    polarity = -1.0 if _covariance(s_c, p_c) < 0 else 1.0
    n_tare = max(1, round(tare_seconds / dt))
    rest = float(np.mean([np.mean(r.position[:n_tare]) for r in recordings]))
    conventions = {"scaling": Scaling(s_off, s_scale, p_off, p_scale), "polarity": polarity,
                   "sensor_reference": reference,
                   "rest_position": rest if center == "tare" else None}
    for a in s_c:  # polarity * s / scale, exactly (a sign change is exact)
        np.divide(a, s_scale, out=a)
        if polarity < 0:
            np.negative(a, out=a)
    for a in p_c:
        np.divide(a, p_scale, out=a)
    return conventions, s_c, p_c


def _total(columns) -> float:
    return float(sum(np.sum(c) for c in columns))


def _shifted(a: np.ndarray, offset: float) -> np.ndarray:
    """``a - offset`` in place (``a`` is a fresh array)."""
    np.subtract(a, offset, out=a)
    return a


def _max_abs(columns: Sequence[np.ndarray]) -> float:
    return float(max(max(np.max(c), -np.min(c)) for c in columns))


def _covariance(s: Sequence[np.ndarray], p: Sequence[np.ndarray]) -> float:
    """Covariance of the concatenated columns (its sign is the correlation's), by dot products."""
    n = sum(c.size for c in s)
    return float(sum(np.dot(a, b) for a, b in zip(s, p, strict=True))) / n \
        - _total(s) / n * _total(p) / n


def centre_and_scale(recording: Recording, center: str) -> tuple[Scaling, np.ndarray,
                                                                 np.ndarray]:
    """One recording's scaling and its normalised sensor and position (eq. 5.10), centred
    by ``center`` as a fit would (compare and the benchmarks use it).

    Parameters
    ----------
    recording : Recording
        A recording with position and sensor.
    center : {"fit", "tare", "track", "recording", "none"}
        Centring mode.

    Returns
    -------
    scaling : Scaling
        Its offsets and scales.
    s, p : numpy.ndarray, shape (n,)
        Normalised sensor and position.

    Raises
    ------
    InputError
        A constant position or sensor column.
    """
    conventions, s, p = prepare_training_data([recording], center)
    return conventions["scaling"], s[0], p[0]
