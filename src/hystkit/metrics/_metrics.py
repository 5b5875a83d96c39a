"""Goodness-of-fit, distortion and hysteresis metrics (thesis chapter 5)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from .._docfill import docfiller
from ._reversals import REVERSAL_DEADBAND, confirmed_reversals

# The Parameters section of the normalised errors of eq. 5.11 (the docstrings' %(normalised_pair)s).
METRIC_ENTRIES = {"normalised_pair": """Parameters
----------
y_true, y_pred : array_like, shape (n,)
    Measured and predicted signal, same unit, n >= 2.
scale : float, optional
    Normalisation of eq. 5.10 in the unit of the signals; default ``max|y_true|``."""}
fill_metric_doc = docfiller(METRIC_ENTRIES.__getitem__)

# Kaiser beta of MATLAB's ``sinad``: its side lobes (~ -350 dB) sit below double
# precision, so no leakage escapes the main lobes of the DC and the fundamental.
_KAISER_BETA = 38.0
# First null of the Kaiser window's transform W(f) ~ sinh(sqrt(beta^2 - (pi*k)^2)) / sqrt(...),
# k in bins: sqrt(beta^2 - (pi*k)^2) turns imaginary and first equals i*pi at
# k0 = sqrt(1 + (beta/pi)^2) = 12.14 bins.  A tone's peak bin can be up to half a bin
# off the true frequency, so its lobe spans peak +- (k0 + 0.5) -> 13 bins each side.
# (Checked numerically: the zero-padded power spectrum of the window drops to the rounding
# floor, ~1e-32 of its peak, exactly at 12.14 bins.)
_LOBE_HALF_WIDTH = math.ceil(math.sqrt(1.0 + (_KAISER_BETA / math.pi) ** 2) + 0.5)


def _as_signal(a: npt.ArrayLike, name: str) -> np.ndarray:
    """Return `a` as a finite 1-D float array of at least 2 samples, else raise ValueError."""
    arr = np.asarray(a, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {arr.shape}")
    if arr.size < 2:
        raise ValueError(f"{name} needs at least 2 samples, got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return arr


def _as_pair(
    a: npt.ArrayLike, b: npt.ArrayLike, names: tuple[str, str]
) -> tuple[np.ndarray, np.ndarray]:
    """Validate two signals with `_as_signal` and check that their lengths match."""
    a_arr, b_arr = _as_signal(a, names[0]), _as_signal(b, names[1])
    if a_arr.size != b_arr.size:
        raise ValueError(
            f"{names[0]} and {names[1]} differ in length ({a_arr.size} vs {b_arr.size})"
        )
    return a_arr, b_arr


def _normalised_error(
    y_true: npt.ArrayLike, y_pred: npt.ArrayLike, scale: float | None
) -> np.ndarray:
    """Return psi - psi_hat, both signals divided by `scale` (eq. 5.10), shape (n,)."""
    t, p = _as_pair(y_true, y_pred, ("y_true", "y_pred"))
    s = float(np.max(np.abs(t))) if scale is None else float(scale)
    if not (math.isfinite(s) and s > 0.0):
        raise ValueError(f"scale must be finite and > 0, got {s} (y_true all zero?)")
    return (t - p) / s  # eq. 5.10


def r2(y_true: npt.ArrayLike, y_pred: npt.ArrayLike) -> float:
    """Ordinary coefficient of determination, ``1 - SS_res / SS_tot``.

    Parameters
    ----------
    y_true, y_pred : array_like, shape (n,)
        Measured and predicted signal, same (any) unit, n >= 2.

    Returns
    -------
    float
        Dimensionless; 1 for a perfect fit, 0 for predicting the mean, negative if worse.

    Raises
    ------
    ValueError
        On bad shapes or non-finite values, or if `y_true` is constant (SS_tot = 0).
    """
    t, p = _as_pair(y_true, y_pred, ("y_true", "y_pred"))
    ss_tot = float(np.sum((t - t.mean()) ** 2))
    # ss_tot can also underflow to 0 for a non-constant but tiny y_true.
    if np.ptp(t) == 0.0 or ss_tot == 0.0:
        raise ValueError("y_true is constant; R^2 is undefined")
    ss_res = float(np.sum((t - p) ** 2))
    return 1.0 - ss_res / ss_tot


@fill_metric_doc
def e_rms_pct(y_true: npt.ArrayLike, y_pred: npt.ArrayLike, scale: float | None = None) -> float:
    """Normalised RMS error in percent of `scale`, eq. 5.11.

    %(normalised_pair)s

    Returns
    -------
    float
        ``100 * sqrt(mean((psi - psi_hat)**2))`` with ``psi = y_true / scale``, in %.
    """
    d = _normalised_error(y_true, y_pred, scale)
    return 100.0 * math.sqrt(float(np.mean(d**2)))  # eq. 5.11


@fill_metric_doc
def e_max_pct(y_true: npt.ArrayLike, y_pred: npt.ArrayLike, scale: float | None = None) -> float:
    """Normalised maximum absolute error in percent of `scale`, eq. 5.11.

    %(normalised_pair)s

    Returns
    -------
    float
        ``100 * max|psi - psi_hat|`` with ``psi = y_true / scale``, in %.
    """
    d = _normalised_error(y_true, y_pred, scale)
    return 100.0 * float(np.max(np.abs(d)))  # eq. 5.11


def sinad_db(x: npt.ArrayLike, fs: float = 1.0) -> float:
    """Signal to noise-and-distortion ratio of one signal, like MATLAB's ``sinad(x)``.

    The one-sided modified periodogram with a Kaiser window (beta = 38) is split into
    the DC main lobe (bins 0..13), the fundamental's main lobe (largest remaining peak
    +- 13 bins; see `_LOBE_HALF_WIDTH`) and the rest, which is noise plus distortion.
    Nothing is removed from `x` beforehand (no detrending).

    A fundamental inside the DC main lobe (a recording of fewer than 13.5 periods of it)
    is refused: the largest remaining peak would then be noise or the lobe's skirt, and the
    tone itself would be discarded with DC (a 1 Hz sine of 1200 samples at 200 Hz, bin 6,
    read about 0 dB). The fundamental is located on the periodogram of ``x`` minus its
    mean, where DC does not hide it. Between 13.5 and 27 periods the two lobes overlap and
    the part of the fundamental's lobe below bin 14 counts as DC: the result reads low
    (measured on a sine with noise: -3 dB at 13.6 periods, -0.3 dB at 16, -0.1 dB at 20).

    Parameters
    ----------
    x : array_like, shape (n,)
        Sampled signal, any unit.  The fundamental should lie more than ~26 bins
        (``26 * fs / n``) away from 0 Hz and fs/2, otherwise the lobes overlap; within 13
        bins it is refused.
    fs : float, default 1.0
        Sampling rate in Hz; the result does not depend on it.

    Returns
    -------
    float
        ``10 log10(P_fund / (P_total - P_dc - P_fund))`` in dB; ``inf`` if nothing is
        left besides DC and fundamental.

    Raises
    ------
    ValueError
        On bad input, ``fs <= 0``, a constant `x`, fewer samples than the lobes need, or a
        fundamental inside the DC main lobe (the message names the samples it needs).
    """
    sig = _as_signal(x, "x")
    if not (math.isfinite(fs) and fs > 0.0):
        raise ValueError(f"fs must be finite and > 0, got {fs}")
    if np.ptp(sig) == 0.0:
        raise ValueError("x is constant; it has no fundamental")
    h = _LOBE_HALF_WIDTH
    n_bins = sig.size // 2 + 1
    if n_bins <= 3 * h + 2:  # DC lobe + a full fundamental lobe + at least one noise bin
        raise ValueError(f"x has {sig.size} samples; sinad_db needs at least {6 * h + 4}")
    # detrend=False: MATLAB removes nothing by hand; the DC lobe is excluded below instead.
    pxx = kaiser_periodogram(sig, fs, _KAISER_BETA)
    _check_fundamental_clears_dc(sig, fs)
    rest = np.ones(n_bins, dtype=bool)
    rest[: h + 1] = False  # DC main lobe
    k = h + 1 + int(np.argmax(pxx[h + 1 :]))  # fundamental = largest non-DC peak
    lo, hi = max(k - h, h + 1), min(k + h, n_bins - 1)
    rest[lo : hi + 1] = False
    p_fund = float(np.sum(pxx[lo : hi + 1]))
    # Summing the remaining bins equals P_total - P_dc - P_fund but cannot cancel to < 0.
    p_noise = float(np.sum(pxx[rest]))
    if p_noise == 0.0:
        return math.inf
    return 10.0 * math.log10(p_fund / p_noise)


def _check_fundamental_clears_dc(sig: np.ndarray, fs: float) -> None:
    """Raise ValueError if the largest non-DC component of `sig` lies in the DC main lobe."""
    h = _LOBE_HALF_WIDTH
    centred = kaiser_periodogram(sig - sig.mean(), fs, _KAISER_BETA)
    k0 = 1 + int(np.argmax(centred[1:]))
    if k0 > h:
        return
    n = sig.size
    f0 = k0 * fs / n
    # its peak bin is the nearest one: beyond the lobe from h + 0.5 periods on
    need, clear = math.ceil((h + 0.5) * n / k0), math.ceil((2 * h + 1) * n / k0)
    raise ValueError(
        f"the fundamental (near {f0:.3g} Hz, bin {k0} of {n} samples) lies inside the DC main "
        f"lobe (bins 0-{h}): the recording is too short for its frequency; SINAD needs "
        f"{h + 0.5:g} periods of it (about {need} samples), and {2 * h + 1} ({clear} samples) "
        f"to keep its lobe clear of DC's")


def kaiser_periodogram(x: np.ndarray, fs: float, beta: float) -> np.ndarray:
    """One-sided power spectral density of `x` with a periodic Kaiser window, no detrending.

    What ``scipy.signal.periodogram(x, fs, window=("kaiser", beta), detrend=False)`` returns
    (density scaling), from numpy alone: scipy.signal costs ~1 s to import, which every
    process scoring a model with SINAD (each worker of ``compare`` / ``generalize``) paid
    for this one call. Tested against scipy's to rounding.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        The signal.
    fs : float
        Sampling rate [Hz].
    beta : float
        Kaiser window shape.

    Returns
    -------
    numpy.ndarray, shape (n // 2 + 1,)
        Power spectral density [unit² / Hz] at ``k fs / n``.
    """
    n = x.size
    window = np.kaiser(n + 1, beta)[:-1]  # periodic ("fftbins"): the symmetric one of n + 1
    pxx = np.abs(np.fft.rfft(x * window)) ** 2 / (fs * float(np.sum(window * window)))
    pxx[1 : n // 2 + (n % 2)] *= 2.0  # one-sided: every bin but DC and (n even) Nyquist
    return pxx


def _sweep_total(x: np.ndarray, deadband: float) -> float:
    """Sum of the sweep heights of `x` between start, confirmed reversals and end.

    A reversal is confirmed once `x` has moved back by more than `deadband` from its
    running extremum (a hysteresis comparator), so noise and flat runs add nothing.
    """
    turns = x[np.r_[0, confirmed_reversals(x, deadband).index, x.size - 1]]
    return float(np.sum(np.abs(np.diff(turns))))


def loop_area(x: npt.ArrayLike, y: npt.ArrayLike) -> float:
    """Normalised hysteresis loop area per input cycle in percent, eq. 5.15.

    Both signals are scaled to [0, 1] (``x_hat = (x - min x) / (max x - min x)``,
    likewise ``y_hat``) and the line integral along the recorded path,
    ``A_hat = 100 / n_cycles * sum_i (y_hat[i] + y_hat[i+1]) / 2 * (x_hat[i+1] - x_hat[i])``
    (trapezoid rule of ``oint y_hat dx_hat``), is returned.  Its sign gives the
    orientation: clockwise in the (x_hat, y_hat) plane is positive, so an output that
    lags the input (counter-clockwise) gives a negative value.  Monotone y(x) gives 0.

    ``n_cycles = max(1, S / 2)``, where S is the summed height of the sweeps of x_hat
    between its start, its reversals and its end: a full cycle sweeps the range up and
    down (S = 2), whatever phase the record starts at.  For a record that starts and
    ends mid-range this is ``n_reversals / 2``; unlike a plain reversal count it also
    gives whole cycles for a record that starts at an extremum.  A reversal counts only
    after x has come back by 1 % of its range, so noise and flat runs are ignored.
    Records shorter than one cycle are normalised as one cycle.

    Parameters
    ----------
    x, y : array_like, shape (n,)
        Input (e.g. displacement) and output (e.g. sensor reading), any units, n >= 2.

    Returns
    -------
    float
        Signed loop area per cycle in % of the unit square; |A_hat| <= 100.

    Raises
    ------
    ValueError
        On bad input, or if x or y is constant (the normalisation is undefined).
    """
    xs, ys = _as_pair(x, y, ("x", "y"))
    x_rng, y_rng = float(np.ptp(xs)), float(np.ptp(ys))
    if x_rng == 0.0 or y_rng == 0.0:
        raise ValueError("x and y must not be constant; the loop cannot be normalised")
    x_hat = (xs - xs.min()) / x_rng
    y_hat = (ys - ys.min()) / y_rng
    n_cycles = max(1.0, _sweep_total(x_hat, REVERSAL_DEADBAND) / 2.0)
    # numpy's trapezoid rule (named trapz before numpy 2), not scipy.integrate's: that import
    # costs ~0.3 s in every process that scores a model
    trapezoid = getattr(np, "trapezoid", None) or np.trapz
    return 100.0 / n_cycles * float(trapezoid(y_hat, x_hat))  # eq. 5.15
