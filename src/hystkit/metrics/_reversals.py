"""The reversals of an input: one hysteresis comparator for cycle counts and cycle cuts.

The loop-area metric counts an input's cycles by its sweeps (:func:`hystkit.metrics.loop_area`,
eq. 5.15) and the per-cycle analysis cuts a recording at the input's minima
(:func:`hystkit.analysis.input_minima`). Both need the same thing: the extrema at which the
input really turned, not the wiggles of sensor noise or the flat runs of a quantised encoder.
A reversal counts only once the input has come back from its running extremum by more than a
dead band (a hysteresis comparator); this module is that comparator, so the two cannot drift
apart.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["REVERSAL_DEADBAND", "Reversals", "confirmed_reversals"]

# A reversal of x counts only after x came back by this fraction of its range,
# so sensor noise and flat runs do not create spurious cycles.
REVERSAL_DEADBAND = 0.01


@dataclass(frozen=True, eq=False)
class Reversals:
    """Confirmed extrema of a signal, from :func:`confirmed_reversals`.

    Parameters
    ----------
    index : numpy.ndarray of int, shape (k,)
        Sample of each confirmed extremum, increasing; of a flat extremum the first sample.
    is_max : numpy.ndarray of bool, shape (k,)
        True for a maximum, False for a minimum (they alternate).
    onset : int
        First sample (of those the comparator visits) where the signal had left the band
        around its first value, so the first sweep's direction was known; -1 if never. Every
        sample between the true crossing of the band and `onset` moves the same way.
    rising_first : bool
        Direction of the first sweep (meaningless when ``onset == -1``).
    """

    index: np.ndarray
    is_max: np.ndarray
    onset: int
    rising_first: bool


def confirmed_reversals(x: np.ndarray, band: float) -> Reversals:
    """Extrema of `x` that a hysteresis comparator with dead band `band` confirms.

    The direction is unknown until `x` leaves the band around its first value; the running
    extremum is then followed, and it is confirmed as a reversal once `x` has come back from
    it by more than `band` (strictly, so a zero band still needs a move back). The extremum
    still open at the end of `x` is not confirmed.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Finite signal, n >= 1 (not checked here: callers validate).
    band : float
        Dead band, in the unit of `x` (>= 0).

    Returns
    -------
    Reversals
        The confirmed extrema in order, and where and which way the first sweep started.
    """
    # Only the first sample of a flat run and the samples where the slope changes sign can be
    # extrema or decide the direction; visiting only those keeps the Python loop short.
    keep = np.flatnonzero(np.r_[True, np.diff(x) != 0.0])
    if keep.size > 2:
        d = np.sign(np.diff(x[keep]))
        keep = keep[np.r_[0, np.flatnonzero(d[1:] != d[:-1]) + 1, keep.size - 1]]
    index: list[int] = []
    is_max: list[bool] = []
    direction, ext, onset, first = 0, 0, -1, 0
    for i in keep[1:].tolist():
        if direction == 0:
            if abs(x[i] - x[0]) > band:
                direction, ext, onset = (1 if x[i] > x[0] else -1), i, i
                first = direction
        elif direction * (x[i] - x[ext]) > 0.0:
            ext = i  # still moving the same way
        elif abs(x[i] - x[ext]) > band:
            index.append(ext)
            is_max.append(direction == 1)
            direction, ext = -direction, i
    return Reversals(index=np.array(index, dtype=np.int64), is_max=np.array(is_max, dtype=bool),
                     onset=onset, rising_first=first == 1)
