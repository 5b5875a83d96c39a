"""Where a recording's sensor offset comes from: the centring modes of a compensator.

A sensor's offset drifts between and within recordings (a soft strain gauge's resting resistance
moved from about 1000 to 1800 ohm between two runs). Every mode except ``recording`` is
*deployable*: the offset used at sample k is computed from sensor samples <= k and numbers stored
in the model file only.

- ``fit``: the training recording's offsets, for every recording.
- ``tare``: the device rests at a known position for the first ``tare_seconds`` of every
  recording; the sensor level there is the recording's zero (a running mean while the window
  fills, so even the tare window itself is causal).
- ``track``: a causal first-order low-pass (exponentially weighted mean, time constant
  ``track_seconds``) of the sensor follows slow drift. What it removes is the sensor's content
  slower than about ``1 / (2 pi track_seconds)``; a measurand that moves faster than that and
  averages to its rest position over ``track_seconds`` passes, a deflection *held* for longer
  than ``track_seconds`` is slowly taken for drift (see docs/centring.md).
- ``recording`` (**oracle**, the protocol of paper 9.2): the whole recording's sensor mean, and
  for scoring its true mean position. Neither exists while the sensor is in use; kept only to
  compare with the document.
- ``none``: no offsets.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CENTERS", "DEFAULT_CENTER", "DEFAULT_TARE_SECONDS", "DEFAULT_TRACK_SECONDS",
           "DEPLOYABLE_CENTERS", "ORACLE_CENTER", "center_label", "sensor_level"]

DEPLOYABLE_CENTERS = ("fit", "tare", "track")
ORACLE_CENTER = "recording"
CENTERS = (*DEPLOYABLE_CENTERS, ORACLE_CENTER, "none")
# Chosen from the measurements in docs/centring.md.
DEFAULT_CENTER = "fit"
DEFAULT_TARE_SECONDS = 2.0
# Ten times the slowest period of the document's excitations (chirp from 0.1 Hz): the tracker's
# low-pass passes 1/(2 pi 100) = 0.0016 Hz, so a 0.1 Hz motion leaks into it by ~1.6 %.
DEFAULT_TRACK_SECONDS = 100.0


def center_label(center: str) -> str:
    """The name shown next to a score: the oracle mode always says that it is one.

    Parameters
    ----------
    center : str
        A centring mode.

    Returns
    -------
    str
        `center`, with `` (oracle)`` appended for ``recording``.
    """
    return f"{center} (oracle)" if center == ORACLE_CENTER else center


def sensor_level(center: str, sensor: np.ndarray, dt: float, *, tare_seconds: float,
                 track_seconds: float) -> np.ndarray | None:
    """Per-sample sensor level of a recording for ``tare`` / ``track``; None for other modes.

    Both are causal: entry k depends on ``sensor[:k + 1]`` only.
    """
    s = np.asarray(sensor, dtype=float)
    if center == "tare":
        n_tare = max(1, round(tare_seconds / dt))
        level = np.cumsum(s[:n_tare]) / np.arange(1, min(n_tare, s.size) + 1)
        return np.concatenate([level, np.full(s.size - level.size, level[-1])])
    if center == "track":
        # Exponentially weighted mean normalised by its weight sum: the running mean while
        # fewer than ~track_seconds have passed, a first-order low-pass afterwards.
        from scipy.signal import lfilter  # here: scipy.signal costs ~0.7 s to import

        a = 1.0 - np.exp(-dt / track_seconds)
        b, den = [a], [1.0, a - 1.0]
        return lfilter(b, den, s) / lfilter(b, den, np.ones_like(s))
    return None
