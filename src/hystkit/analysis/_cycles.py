"""Splitting a recording into load-unload cycles of its input (figs. 4.16-4.17).

A cycle runs from one minimum of the input (the position) to the next: loading from the
minimum to the maximum, unloading back. Minima are found with the hysteresis comparator the
loop-area metric counts sweeps with (:func:`hystkit.metrics.confirmed_reversals`): a reversal
counts only after the input has come back by a dead band (1 % of its range by default), so
sensor noise and the flat runs of a quantised encoder make no spurious cycles. The bounds partition the
record: the part before the first minimum and after the last are kept as incomplete pieces,
so the pieces put back together give the whole recording.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import numpy.typing as npt

from ..metrics import REVERSAL_DEADBAND, confirmed_reversals

__all__ = ["DEFAULT_DEADBAND", "cycle_bounds", "input_minima", "split_cycles"]

# Fraction of the input range the input must come back by before a reversal counts: the
# loop-area metric's, with the same comparator (hystkit.metrics.confirmed_reversals).
DEFAULT_DEADBAND = REVERSAL_DEADBAND


def input_minima(x: npt.ArrayLike, deadband: float = DEFAULT_DEADBAND) -> np.ndarray:
    """Sample indices of the input's confirmed minima; complete cycles run from each to the next.

    Parameters
    ----------
    x : array_like, shape (n,)
        Input signal (position [mm]), finite, not constant, n >= 2.
    deadband : float
        A reversal counts once `x` has come back from its running extremum by more than
        ``deadband * (max x - min x)``; in [0, 0.5).

    Returns
    -------
    ndarray of int, shape (k,)
        Increasing; of a flat minimum the first sample. The first sample counts when the
        record starts by rising from no higher than its first confirmed minimum (plus the
        dead band).

    Raises
    ------
    ValueError
        Bad `x` (not 1-D, under 2 samples, non-finite, constant) or `deadband`.
    """
    xs = np.asarray(x, dtype=float)
    if xs.ndim != 1 or xs.size < 2:
        raise ValueError(f"x must be 1-D with at least 2 samples, got shape {xs.shape}")
    if not np.all(np.isfinite(xs)):
        raise ValueError("x contains NaN or infinite values")
    span = float(np.ptp(xs))
    if span == 0.0:
        raise ValueError("x is constant; it has no cycles")
    if not 0.0 <= deadband < 0.5:
        raise ValueError(f"deadband must lie in [0, 0.5), got {deadband}")
    return np.array(_confirmed_minima(xs, deadband * span), dtype=np.int64)


def cycle_bounds(x: npt.ArrayLike, deadband: float = DEFAULT_DEADBAND) -> np.ndarray:
    """Cut points of the record: the input's minima (:func:`input_minima`) with 0 and ``n``.

    Parameters
    ----------
    x : array_like, shape (n,)
        Input signal (position [mm]), finite, not constant, n >= 2.
    deadband : float, default 0.01
        Reversal dead band as a fraction of the input's range (see :func:`input_minima`).

    Returns
    -------
    ndarray of int, shape (k + 2,) at most
        ``[0, m_1, ..., m_k, n]``, strictly increasing (0 is not repeated when the first
        minimum is the first sample). Complete cycles are ``[m_i, m_{i+1}]``; ``[0, m_1)`` and
        ``[m_k, n)`` are the incomplete head and tail.

    Raises
    ------
    ValueError
        Bad `x` or `deadband` (see :func:`input_minima`).
    """
    return bounds_of(input_minima(x, deadband), np.asarray(x).shape[0])


def bounds_of(minima: np.ndarray, n: int) -> np.ndarray:
    """``[0, *minima, n]`` without repeating 0 when the first minimum is the first sample."""
    return np.array([0, *(int(m) for m in minima if m > 0), n], dtype=np.int64)


def _confirmed_minima(x: np.ndarray, band: float) -> list[int]:
    """Indices of the minima the hysteresis comparator with dead band `band` confirms.

    The comparator is the loop-area metric's (:func:`hystkit.metrics.confirmed_reversals`).
    A record that starts by rising starts at a minimum only if that start (the lowest sample
    before the input left the band) lies no higher than the first confirmed minimum (plus the
    band): a sine started at mid-range has no cycle before its first minimum.
    """
    rev = confirmed_reversals(x, band)
    minima = rev.index[~rev.is_max].tolist()
    if rev.onset >= 0 and rev.rising_first and minima:
        start = int(np.argmin(x[: rev.onset + 1]))
        if x[start] <= x[minima[0]] + band:
            minima.insert(0, start)
    return minima


def split_cycles(bounds: npt.ArrayLike, *arrays: npt.ArrayLike) -> list[tuple[np.ndarray, ...]]:
    """Cut each of `arrays` at `bounds` (from :func:`cycle_bounds`) into consecutive pieces.

    Parameters
    ----------
    bounds : array_like of int
        ``[0, ..., n]``, strictly increasing.
    *arrays : array_like, shape (n,)
        Signals on the same samples (time, position, outputs).

    Returns
    -------
    list of tuple of ndarray
        One tuple per piece ``[bounds[i], bounds[i+1])``, holding that piece of every array;
        concatenated again they give the arrays back. The first and last piece are the
        incomplete head and tail when the record does not start or end at a minimum.
    """
    b = np.asarray(bounds, dtype=np.int64)
    columns = [np.asarray(a) for a in arrays]
    for a in columns:
        if a.shape[0] != b[-1]:
            raise ValueError(f"an array has {a.shape[0]} samples, the bounds end at {b[-1]}")
    return [tuple(a[lo:hi] for a in columns) for lo, hi in pairwise(b)]
