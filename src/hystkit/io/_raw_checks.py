"""Checks of a raw recording's samples, chunk by chunk: finite scope voltages, uniform time.

Each check names the first bad sample through the reader's ``fail`` (file, column, row); the
scans are numba loops that stop at the first bad value instead of masking the whole chunk.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numba import njit

from hystkit._kernel_inputs import read_only
from hystkit.errors import InputError

from ._raw_format import MAX_VOLTAGE

__all__ = ["MAX_STEP_DEVIATION", "check_time_steps", "check_values"]

MAX_STEP_DEVIATION = 0.01  # as for recordings: relative to 1/fs

Fail = Callable[..., InputError]


def check_values(values: np.ndarray, column: str, start: int, fail: Fail, *,
                 n_samples: int | None, from_csv: bool) -> None:
    """Refuse a missing, infinite or (outside ``time``) out-of-range value of one chunk."""
    values = read_only(values)
    i = _first_nonfinite(values)
    if i < 0 and column != "time":
        j = _first_beyond(values, MAX_VOLTAGE)
        if j >= 0:
            raise fail(f"value {values[j]:.6g} V is not a scope reading (hystkit "
                       f"accepts voltages up to {MAX_VOLTAGE:g} V in magnitude)",
                       column, start + j)
    if i >= 0:
        last = start + i + 1 == n_samples if n_samples else False
        problem = "missing or NaN value" if np.isnan(values[i]) else "infinite value"
        if from_csv and np.isnan(values[i]):
            problem += " (a short line: if it is the last one, the file is truncated)"
        elif last:
            problem += " in the last sample (truncated?)"
        raise fail(problem, column, start + i)


def check_time_steps(t: np.ndarray, t_prev: float | None, start: int, fs: float,
                     fail: Fail) -> float:
    """Refuse a time step off 1/fs (across chunk borders via `t_prev`); the chunk's last time."""
    i = _first_bad_step(read_only(t), np.nan if t_prev is None else t_prev, fs, MAX_STEP_DEVIATION)
    if i >= 0:
        previous = float(t[i - 1] if i else t_prev)
        step = float(t[i]) - previous  # Python floats: a huge step is inf, not a warning
        kind = ("time goes backwards or repeats" if step <= 0 else
                f"a gap of {step * fs - 1:.6g} samples (dropped data?)"
                if step * fs > 1.5 else "non-uniform sampling")
        raise fail(f"{kind}: {t[i]:.12g} s follows {previous:.12g} s, but "
                   f"1/fs = {1 / fs:.6g} s", "time", start + i)
    return float(t[-1])


@njit(cache=True, nogil=True)
def _first_nonfinite(x):
    for i in range(x.size):
        if not np.isfinite(x[i]):
            return i
    return -1


@njit(cache=True, nogil=True)
def _first_beyond(x, limit):
    for i in range(x.size):
        if abs(x[i]) > limit:
            return i
    return -1


@njit(cache=True, nogil=True)
def _first_bad_step(t, t_prev, fs, tol):
    """First index whose step from the previous time deviates from 1/fs by more than `tol`."""
    prev = t[0] - 1.0 / fs if np.isnan(t_prev) else t_prev
    for i in range(t.size):
        if abs((t[i] - prev) * fs - 1.0) > tol:
            return i
        prev = t[i]
    return -1

