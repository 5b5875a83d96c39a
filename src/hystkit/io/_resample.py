"""Bring a recording with jittered or non-uniform time onto a uniform grid (``--resample HZ``).

Method (documented in ``docs/own_data.md`` and ``--help``):

1. Gaps are refused: a step longer than ``MAX_GAP_STEPS`` median steps *and* longer than one
   step of the new grid would have samples invented across it; the message names the row.
2. At, above or just below (``DECIMATION_BELOW``) the file's mean rate (samples per second):
   position and sensor are interpolated linearly at the grid times ``t[0] + k / HZ``. The error of linear interpolation is at most
   ``h**2 / 8 * max|f''|`` for a bracketing step h, far below the sensor's noise for signals
   that the file samples well.
3. Further below (decimating): first linearly onto a uniform grid at the mean rate, then a
   zero-phase Butterworth low-pass (order ``FILTER_ORDER``, forwards and backwards, so no
   delay: a delay between position and sensor would look like hysteresis) at
   ``LOWPASS_FRACTION`` x HZ, then linearly onto the new grid. Without the low-pass, content
   above HZ / 2 would fold into the band the model is fitted on.

Both columns go through the same operations, so their relative timing is untouched.
"""

from __future__ import annotations

import numpy as np

from ._cells import Where

__all__ = ["DECIMATION_BELOW", "FILTER_ORDER", "LOWPASS_FRACTION", "MAX_GAP_STEPS", "resample_arrays",
           "time_gaps"]

MAX_GAP_STEPS = 3.0
LOWPASS_FRACTION = 0.4  # of the new rate: 80 % of its Nyquist frequency
FILTER_ORDER = 8  # one way; forwards-backwards doubles the attenuation
DECIMATION_BELOW = 0.95  # low-pass only when the new rate is below 95 % of the mean rate
_MIN_FILTERED = 3 * (2 * (FILTER_ORDER // 2) + 1)  # sosfiltfilt's default padding
_SAME_RATE = 1e-9  # relative rounding allowance: a grid point at the last sample is kept


def time_gaps(time: np.ndarray) -> np.ndarray:
    """Where a time column has gaps: steps longer than `MAX_GAP_STEPS` median steps.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sample times [s], increasing.

    Returns
    -------
    ndarray of int
        Indices i with ``time[i + 1] - time[i]`` a gap; empty for none.
    """
    step = np.diff(time)
    if step.size == 0:
        return np.zeros(0, dtype=np.intp)
    return np.flatnonzero(step > MAX_GAP_STEPS * float(np.median(step)))


def resample_arrays(arrays: dict[str, np.ndarray], rate_hz: float,
                    where: Where) -> dict[str, np.ndarray]:
    """Return `arrays` (``time`` [s] and the signals) on the uniform grid ``t0 + k / rate_hz``.

    Parameters
    ----------
    arrays : dict of str to ndarray, shape (n,)
        ``time`` strictly increasing [s] and finite signal columns of the same length.
    rate_hz : float
        The new sampling rate [Hz].
    where : Where
        Names file and columns in messages.

    Returns
    -------
    dict of str to ndarray, shape (m,)
        ``m = floor((t[-1] - t[0]) * rate_hz) + 1`` samples from ``t[0]``; the grid never
        extends beyond the last sample (no extrapolation).

    Raises
    ------
    InputError
        A gap (see the module notes) naming the row and file line, or fewer than 2 samples
        on the new grid.
    """
    time = arrays["time"]
    step = np.diff(time)
    median = float(np.median(step))
    limit = max(MAX_GAP_STEPS * median, 1.0 / rate_hz)
    gaps = np.flatnonzero(step > limit)
    if gaps.size:
        i = int(gaps[0])
        raise where.fail(f"gap of {step[i]:.6g} s after {time[i]:.12g} s: longer than "
                         f"{MAX_GAP_STEPS:g} median steps ({median:.6g} s) and than one step of "
                         f"the {rate_hz:g} Hz grid; --resample does not invent data across a "
                         f"gap: split the recording there (--gaps split)", "time", i + 1)
    n_out = int(np.floor((time[-1] - time[0]) * rate_hz * (1 + _SAME_RATE))) + 1
    if n_out < 2:
        raise where.fail(f"the recording lasts {time[-1] - time[0]:.6g} s: less than 2 samples "
                         f"at {rate_hz:g} Hz")
    grid = time[0] + np.arange(n_out) / rate_hz
    grid[-1] = min(grid[-1], time[-1])  # rounding must not step past the last sample
    own_rate = (time.size - 1) / (time[-1] - time[0])  # the mean rate
    signals = {name: values for name, values in arrays.items() if name != "time"}
    if rate_hz < own_rate * DECIMATION_BELOW:
        if time.size <= _MIN_FILTERED:
            raise where.fail(f"{time.size} samples are too few to low-pass before "
                             f"decimating (more than {_MIN_FILTERED} needed); resample at or "
                             f"above the file's mean rate ({own_rate:.6g} Hz)")
        time, signals = _low_pass(time, signals, own_rate, rate_hz)
    out = {"time": grid}
    out.update({name: np.interp(grid, time, values) for name, values in signals.items()})
    return out


def _low_pass(time: np.ndarray, signals: dict[str, np.ndarray], own_rate: float,
              rate_hz: float) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Signals on a uniform grid at the file's mean rate, low-passed for `rate_hz`."""
    from scipy.signal import butter, sosfiltfilt  # here: only resampling needs scipy.signal

    n = int(np.floor((time[-1] - time[0]) * own_rate * (1 + _SAME_RATE))) + 1
    uniform = time[0] + np.arange(n) / own_rate
    uniform[-1] = min(uniform[-1], time[-1])
    sos = butter(FILTER_ORDER, LOWPASS_FRACTION * rate_hz, fs=own_rate, output="sos")
    return uniform, {name: sosfiltfilt(sos, np.interp(uniform, time, values))
                     for name, values in signals.items()}
