"""Filtering and resampling of recordings as in the document's lab pipeline (sec. 4.3.1)."""

from __future__ import annotations

import numpy as np
from scipy import signal

__all__ = ["downsample", "lowpass_zero_phase"]


def lowpass_zero_phase(x: np.ndarray, fs: float, cutoff: float = 20.0, order: int = 2,
                       axis: int = -1) -> np.ndarray:
    """Zero-phase Butterworth low-pass (forward-backward, ``filtfilt``), eq. 4.1.

    Parameters
    ----------
    x : array
        Signal(s) sampled at ``fs`` [Hz].
    fs : float
        Sample rate [Hz].
    cutoff : float
        -3 dB frequency of the one-way filter [Hz] (20 Hz in the document).
    order : int
        One-way order (2 in the document); the zero-phase result has twice the roll-off.
    axis : int
        Axis of the samples.

    Returns
    -------
    numpy.ndarray
        The filtered signal(s), the shape of `x`.

    Raises
    ------
    ValueError
        If `cutoff` is not between 0 and ``fs / 2``.
    """
    return signal.sosfiltfilt(butterworth_sections(fs, cutoff, order), x, axis=axis)


def butterworth_sections(fs: float, cutoff: float, order: int) -> np.ndarray:
    """The one-way Butterworth low-pass of eq. 4.1 as second-order sections; ValueError unless
    0 < `cutoff` < `fs` / 2 (the spectrum's response is of the same design)."""
    if not 0 < cutoff < fs / 2:
        raise ValueError(f"cutoff {cutoff:g} Hz must lie between 0 and fs/2 = {fs / 2:g} Hz")
    return signal.butter(order, cutoff, fs=fs, output="sos")


def downsample(x: np.ndarray, fs: float, fs_out: float, axis: int = -1) -> np.ndarray:
    """Keep every ``fs / fs_out``-th sample (the caller low-passes first, as the lab does).

    Parameters
    ----------
    x : numpy.ndarray
        Signal(s) sampled at `fs`.
    fs : float
        Sample rate of `x` [Hz].
    fs_out : float
        Output sample rate [Hz]; `fs` must be an integer multiple of it.
    axis : int
        Axis of the samples.

    Returns
    -------
    numpy.ndarray
        Samples 0, ``fs / fs_out``, ... of `x` along `axis`.

    Raises
    ------
    ValueError
        If `fs` is not an integer multiple of `fs_out`.
    """
    factor = fs / fs_out
    if abs(factor - round(factor)) > 1e-9 or round(factor) < 1:
        raise ValueError(f"fs = {fs} Hz is not an integer multiple of fs_out = {fs_out} Hz")
    return np.take(x, np.arange(0, np.shape(x)[axis], round(factor)), axis=axis)
