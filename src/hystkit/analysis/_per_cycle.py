"""Per-cycle loop area, offset and drift of one or more sensor signals (figs. 4.13, 4.16-4.17).

For every complete cycle of the input (:func:`~hystkit.analysis.cycle_bounds`, minimum to
minimum) and every output signal (dR1/R1, dR2/R2 and their difference, or any other):

* ``area``: the enclosed area ``oint y dx`` [unit of x * unit of y] by the trapezoid rule over
  the cycle's samples *including* the next cycle's first one, so the loop is closed and the
  areas of consecutive cycles add up to the line integral over all of them. Positive is
  clockwise in the (x, y) plane, as in :func:`hystkit.metrics.loop_area`;
* ``area_pct``: the document's normalised loop area of the cycle (eq. 5.15), from
  :func:`hystkit.metrics.loop_area` on the same samples;
* ``offset``: the mean of y over the cycle's own samples (the loop's level);
* ``drift_from_previous``: the offset minus the previous cycle's (None for the first cycle).

The drift rate over the recording is the least-squares slope of the offsets against the cycle
times (the mean time of each cycle's samples), per hour, with its standard error inflated for
autocorrelated offsets (:func:`drift_rate`); a drift that is linear in time gives exactly its
slope whatever the loop shape, since a whole cycle's mean of the periodic part does not depend
on the cycle. A drift that is not a line (a decaying creep transient) is flagged: the slope is
then an average over the record.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..metrics import loop_area
from ._autocorr import ar1_inflation, lag1
from ._cycles import DEFAULT_DEADBAND, bounds_of, input_minima

__all__ = ["CycleTable", "DriftRate", "cycle_table", "drift_rate", "enclosed_area"]


def enclosed_area(x: npt.ArrayLike, y: npt.ArrayLike) -> float:
    """Signed area ``oint y dx`` of the path (x, y) by the trapezoid rule [x unit * y unit].

    The path is integrated as given (close it by repeating its first point at the end for a
    loop). Clockwise loops are positive: for ``x = a sin t``, ``y = b sin(t + phi)`` over one
    period the result is ``pi a b sin(phi)``.

    Parameters
    ----------
    x, y : array_like, shape (n,)
        The path's coordinates.

    Returns
    -------
    float
        Signed area [x unit * y unit], positive for a clockwise loop.
    """
    xs, ys = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return float(np.sum(0.5 * (ys[1:] + ys[:-1]) * np.diff(xs)))


@dataclass(frozen=True)
class DriftRate:
    """Least-squares slope of the cycle offsets against time, with an honest error.

    ``per_hour`` and ``stderr_per_hour`` [signal unit per hour]; ``per_cycle`` the slope
    times the mean cycle duration [signal unit]; ``n_cycles`` the cycles it rests on (the
    standard error needs 3 or more; with 2 it is None). The standard error allows for
    autocorrelated offsets (see :func:`drift_rate`): ``residual_lag1`` and ``n_effective``
    say by how much. ``half_slopes_per_hour`` and ``linear`` compare the slopes of the first
    and second half of the cycles (6 cycles or more, else None).

    Parameters
    ----------
    per_hour : float
        Slope [signal unit per hour].
    stderr_per_hour : float or None
        Its standard error [signal unit per hour]; None with 2 cycles.
    per_cycle : float
        Slope times the mean cycle duration [signal unit].
    n_cycles : int
        Cycles the fit rests on.
    residual_lag1 : float or None
        Lag-1 autocorrelation of the residuals about the line; None with 2 cycles.
    n_effective : float or None
        Effective number of independent cycles, ``n (1 - r1) / (1 + r1)`` (``n`` for
        ``r1 <= 0``); None with 2 cycles.
    half_slopes_per_hour : tuple of (float, float, float, float) or None
        Slope and standard error of the first half, then of the second half [per hour].
    linear : bool or None
        False when the two half slopes differ by more than three standard errors of their
        difference: the drift is not a line and ``per_hour`` is an average.
    """

    per_hour: float
    stderr_per_hour: float | None
    per_cycle: float
    n_cycles: int
    residual_lag1: float | None = None
    n_effective: float | None = None
    half_slopes_per_hour: tuple[float, float, float, float] | None = None
    linear: bool | None = None


# Cycles each half needs for its own slope and error in the linearity check.
_MIN_HALF = 3
# Half slopes further apart than this many standard errors of their difference mark the drift
# as not linear. 3 rather than 2: each half's error comes from half the cycles and is itself
# optimistic under autocorrelation (tests/analysis/test_cycle_analysis.py measures the rate
# of false alarms on straight lines in AR(1) noise).
_LINE_SIGMAS = 3.0


def _slope(t: np.ndarray, y: np.ndarray) -> tuple[float, float | None, float | None]:
    """Least-squares slope [per s], its AR(1)-inflated standard error and the residual lag-1."""
    tc = t - t.mean()
    sxx = float(np.sum(tc * tc))
    slope = float(np.sum(tc * (y - y.mean())) / sxx)
    if t.size <= 2:
        return slope, None, None
    resid = y - y.mean() - slope * tc
    rho = lag1(resid)
    iid = math.sqrt(float(np.sum(resid * resid)) / (t.size - 2) / sxx)
    return slope, ar1_inflation(rho) * iid, rho


def drift_rate(t_cycle: npt.ArrayLike, offset: npt.ArrayLike,
               mean_duration: float) -> DriftRate:
    """Slope of `offset` against `t_cycle` [s], per hour, its standard error and a line check.

    The offsets of neighbouring cycles are alike (creep, temperature), so the i.i.d. standard
    error of the slope is too small. It is multiplied by ``sqrt((1 + r1) / (1 - r1))``, with
    ``r1`` the lag-1 autocorrelation of the residuals about the line: the AR(1) effective
    sample size ``n_eff = n (1 - r1) / (1 + r1)`` (positive ``r1`` only; the same inflation as
    the settling fit). ``r1`` from few cycles is biased low, so the error stays somewhat
    optimistic for short records. The first and second half of the cycles are fitted apart,
    each with its own inflated error; slopes that differ by more than three times the error of
    their difference mark the drift as not linear.

    Parameters
    ----------
    t_cycle : array_like, shape (k,)
        Time of each cycle [s] (the mean time of its samples), k >= 2.
    offset : array_like, shape (k,)
        Offset of each cycle, any unit.
    mean_duration : float
        Mean cycle duration [s], for ``per_cycle``.

    Returns
    -------
    DriftRate
        Slope per hour, its standard error (None for k = 2), slope per cycle, the residual
        lag-1 autocorrelation and effective sample size, the half slopes and the line check.

    Raises
    ------
    ValueError
        Fewer than 2 cycles.
    """
    t, y = np.asarray(t_cycle, dtype=float), np.asarray(offset, dtype=float)
    if t.size < 2:
        raise ValueError("a drift rate needs at least 2 cycles")
    slope, stderr, rho = _slope(t, y)
    n_eff = None if rho is None else t.size * (1 - max(rho, 0.0)) / (1 + max(rho, 0.0))
    halves, linear = None, None
    if t.size >= 2 * _MIN_HALF:
        h = t.size // 2
        (s1, e1, _), (s2, e2, _) = _slope(t[:h], y[:h]), _slope(t[h:], y[h:])
        halves = tuple(3600.0 * v for v in (s1, e1, s2, e2))
        rounding = 1e-9 * max(abs(s1), abs(s2))  # a noise-free line has zero errors
        linear = bool(abs(s1 - s2) <= _LINE_SIGMAS * math.hypot(e1, e2) + rounding)
    return DriftRate(per_hour=3600.0 * slope,
                     stderr_per_hour=None if stderr is None else 3600.0 * stderr,
                     per_cycle=slope * mean_duration, n_cycles=int(t.size), residual_lag1=rho,
                     n_effective=n_eff, half_slopes_per_hour=halves, linear=linear)


@dataclass(frozen=True, eq=False)
class CycleTable:
    """Per-cycle results of :func:`cycle_table`.

    Parameters
    ----------
    bounds : ndarray of int
        All cut points ``[0, m_1, ..., m_k, n]`` (:func:`~hystkit.analysis.cycle_bounds`).
    start, stop : ndarray of int, shape (k - 1,)
        Sample range ``[start, stop)`` of each complete cycle (numbered 1.. in order).
    t_start, t_stop, t_mid : ndarray, shape (k - 1,)
        Time of the first sample, of the closing sample and the mean time of each cycle [s].
    area, area_pct, offset : dict of str to ndarray, shape (k - 1,)
        Per signal: enclosed area, eq. 5.15 loop area [%], mean level (see the module).
    drift : dict of str to DriftRate
        Per signal, over all complete cycles (absent with fewer than 2 cycles).
    """

    bounds: np.ndarray
    start: np.ndarray
    stop: np.ndarray
    t_start: np.ndarray
    t_stop: np.ndarray
    t_mid: np.ndarray
    area: dict[str, np.ndarray]
    area_pct: dict[str, np.ndarray]
    offset: dict[str, np.ndarray]
    drift: dict[str, DriftRate]

    @property
    def n_cycles(self) -> int:
        """Number of complete cycles."""
        return int(self.start.size)

    def drift_between(self, name: str) -> np.ndarray:
        """Offset change from the previous cycle, shape (k - 2,), for cycles 2..k."""
        return np.diff(self.offset[name])

    def rows(self) -> list[dict]:
        """One plain dict per (cycle, signal): the CSV rows."""
        out = []
        for k in range(self.n_cycles):
            for name in self.area:
                out.append({
                    "cycle": k + 1, "signal": name,
                    "t_start_s": float(self.t_start[k]), "t_stop_s": float(self.t_stop[k]),
                    "t_mid_s": float(self.t_mid[k]), "area": float(self.area[name][k]),
                    "area_pct": float(self.area_pct[name][k]),
                    "offset": float(self.offset[name][k]),
                    "drift_from_previous": (float(self.offset[name][k]
                                                  - self.offset[name][k - 1]) if k else None),
                })
        return out


def cycle_table(t: npt.ArrayLike, x: npt.ArrayLike, signals: Mapping[str, npt.ArrayLike],
                deadband: float = DEFAULT_DEADBAND) -> CycleTable:
    """Loop area, offset and drift of every complete input cycle, for each signal.

    Parameters
    ----------
    t : array_like, shape (n,)
        Time [s].
    x : array_like, shape (n,)
        Input (position [mm]); its minima cut the cycles.
    signals : mapping of str to array_like, shape (n,)
        Outputs, e.g. ``{"dR1/R1": ..., "dR2/R2": ..., "dR1/R1 - dR2/R2": ...}``.
    deadband : float
        Reversal dead band as a fraction of the input range (:func:`cycle_bounds`).

    Returns
    -------
    CycleTable

    Raises
    ------
    ValueError
        Arrays of different lengths, non-finite values, a constant input, or no complete
        cycle (the message says how many minima were found).
    """
    ts, xs = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    ys = {name: np.asarray(y, dtype=float) for name, y in signals.items()}
    for name, y in {"t": ts, **ys}.items():
        if y.shape != xs.shape:
            raise ValueError(f"{name} has shape {y.shape}, the input {xs.shape}")
        if not np.all(np.isfinite(y)):
            raise ValueError(f"{name} contains NaN or infinite values")
    minima = input_minima(xs, deadband)
    bounds = bounds_of(minima, xs.size)
    if minima.size < 2:
        raise ValueError(f"the input has {minima.size} confirmed minimum/minima, so no complete "
                         "cycle (minimum to minimum); record at least one full cycle")
    start, stop = minima[:-1], minima[1:]
    area, area_pct, offset = {}, {}, {}
    for name, y in ys.items():
        area[name] = np.array([enclosed_area(xs[a:b + 1], y[a:b + 1])
                               for a, b in zip(start, stop, strict=True)])
        area_pct[name] = np.array([loop_area(xs[a:b + 1], y[a:b + 1])
                                   for a, b in zip(start, stop, strict=True)])
        offset[name] = np.array([y[a:b].mean() for a, b in zip(start, stop, strict=True)])
    t_mid = np.array([ts[a:b].mean() for a, b in zip(start, stop, strict=True)])
    mean_duration = float(np.mean(ts[stop] - ts[start]))
    drift = ({name: drift_rate(t_mid, offset[name], mean_duration) for name in ys}
             if start.size >= 2 else {})
    return CycleTable(bounds=bounds, start=start, stop=stop, t_start=ts[start], t_stop=ts[stop],
                      t_mid=t_mid, area=area, area_pct=area_pct, offset=offset, drift=drift)
