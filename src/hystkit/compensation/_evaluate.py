"""Scores of a compensator on a recording (sec. 5.3.3-5.3.6): the numbers of table 5.5."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..io import Recording
from ..metrics import e_max_pct, e_rms_pct, loop_area, r2, sinad_db
from ._compensator import Compensator

__all__ = ["evaluate"]


def evaluate(compensator: Compensator, recording: Recording) -> dict:
    """Compare the compensated and the straight-line position with the measured one.

    With ``center="recording"`` the measured position is centred on its own mean, as in
    paper 9.2; the errors in per cent are relative to the fitting recording's max |position|
    (eq. 5.10-5.11). ``loop_area`` is the normalised loop area (eq. 5.15) of the estimate
    against the measured position (0 for a perfect compensator); ``sensor_loop_area`` is that
    of the raw sensor, for comparison.

    Returns
    -------
    dict
        ``r2, e_rms_pct, e_max_pct, sinad_db, loop_area`` of the compensator, the same with a
        ``linear_`` prefix for the baseline line, ``sensor_loop_area``, ``n_samples``, ``center``,
        ``extrapolated_fraction`` (share of samples outside the sensor range seen in training).
    """
    if not recording.has_position():
        raise InputError(f"{recording.source}: column 'position' is needed to evaluate")
    position = recording.position
    mean = float(np.mean(position)) if compensator.center == "recording" else None
    estimate = compensator.estimate(recording, position_mean=mean)
    linear = compensator.estimate_linear(recording, position_mean=mean)
    scale = compensator.scaling.position_scale
    scores = {"n_samples": recording.n_samples, "center": compensator.center,
              "extrapolated_fraction": compensator.extrapolated_fraction(recording)}
    for prefix, guess in (("", estimate), ("linear_", linear)):
        scores[f"{prefix}r2"] = r2(position, guess)
        scores[f"{prefix}e_rms_pct"] = e_rms_pct(position, guess, scale=scale)
        scores[f"{prefix}e_max_pct"] = e_max_pct(position, guess, scale=scale)
        scores[f"{prefix}sinad_db"] = _sinad_or_none(guess, recording.fs)
        scores[f"{prefix}loop_area"] = _loop_area_or_none(position, guess)
    scores["sensor_loop_area"] = _loop_area_or_none(position, recording.sensor)
    return scores


def _loop_area_or_none(x: np.ndarray, y: np.ndarray) -> float | None:
    """eq. 5.15 normalises by the range of y: undefined (None) for a constant estimate."""
    return None if np.ptp(y) == 0 else loop_area(x, y)


def _sinad_or_none(x: np.ndarray, fs: float) -> float | None:
    """SINAD needs a periodogram long enough to separate the tone (and JSON has no inf)."""
    try:
        value = sinad_db(x, fs)
    except ValueError:
        return None
    return value if np.isfinite(value) else None
