"""Streaming anti-alias decimation: linear-phase FIR stages with explicit state.

Scope recordings (1-6.25 MHz) are brought down to a few times the output rate before the
document's zero-phase Butterworth (eq. 4.1) runs on the small signal. Each stage is a Kaiser-
window FIR low-pass evaluated only at the kept samples (polyphase cost: ``len(taps) / factor``
multiply-adds per input sample). Its output ``k`` is *centred* on input sample ``k * factor``,
so the filter delay is compensated exactly and a chain of stages keeps output ``k`` at raw
sample ``k * D``. At both ends the signal is extended by point reflection (as scipy's
``filtfilt`` pads), so every output exists, including the first, and slopes at the ends are
not bent.

State is explicit (:class:`DecimatorState`): feeding a signal in chunks of any size gives the
outputs of feeding it whole, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy import signal

__all__ = ["Decimator", "DecimatorState", "decimator_flush", "decimator_init", "decimator_step",
           "design_chain"]


@dataclass(frozen=True, eq=False)
class Decimator:
    """One FIR decimation stage: keep every ``factor``-th sample of the low-passed input.

    Parameters
    ----------
    factor : int
        Decimation factor R >= 1.
    taps : ndarray, shape (L,)
        Symmetric (linear-phase) FIR taps, L odd, unit DC gain.
    anchor : int
        Samples of the straight line fitted at each end to centre the end extension on
        (see :func:`_odd_extension`).
    """

    factor: int
    taps: np.ndarray
    anchor: int = 1

    @property
    def half(self) -> int:
        """Half the filter length, (L - 1) / 2: the samples needed either side of a centre."""
        return (self.taps.size - 1) // 2

    @classmethod
    def design(cls, fs: float, factor: int, f_pass: float, f_stop: float,
               atten_db: float = 100.0) -> Decimator:
        """Kaiser-window low-pass, flat to `f_pass` and `atten_db` down from `f_stop` [Hz].

        The ripple in the pass band is ``10**(-atten_db/20)`` (1e-5 for 100 dB).
        """
        if factor == 1:
            return cls(1, np.ones(1), 1)
        if not 0 < f_pass < f_stop <= fs / 2:
            raise ValueError(f"need 0 < f_pass {f_pass} < f_stop {f_stop} <= fs/2 {fs / 2} Hz")
        numtaps, beta = signal.kaiserord(atten_db, (f_stop - f_pass) / (0.5 * fs))
        numtaps += 1 - numtaps % 2  # odd: a whole-sample delay that the centring removes
        taps = signal.firwin(numtaps, 0.5 * (f_pass + f_stop), window=("kaiser", beta), fs=fs)
        # End fits over at most 1/(20 f_pass): long enough to average a scope's per-sample noise
        # at MHz rates, short enough that the signal's curvature does not bias them.
        anchor = max(1, int(fs / (20 * f_pass)))
        return cls(int(factor), taps / taps.sum(), anchor)


def design_chain(fs: float, factor: int, f_pass: float,
                 atten_db: float = 100.0) -> tuple[Decimator, ...]:
    """Stages that decimate by `factor` in total, protecting ``[0, f_pass]`` [Hz].

    The last stage stops at its output Nyquist frequency (nothing aliases at the
    intermediate rate); earlier stages only stop the bands that would fold into what the
    last stage passes. Large factors are split in two (the first stage takes the bulk with a
    wide transition band), which costs about half the multiply-adds of a single stage.

    Parameters
    ----------
    fs : float
        Input sample rate [Hz].
    factor : int
        Total decimation factor (>= 1).
    f_pass : float
        Upper edge of the protected band [Hz].
    atten_db : float
        Stop-band attenuation of each stage [dB].

    Returns
    -------
    tuple of Decimator
        No stage for ``factor == 1``, otherwise one or two stages whose factors multiply to
        `factor`.

    Raises
    ------
    ValueError
        If `factor` < 1, or the bands do not fit below a stage's Nyquist frequency.
    """
    factor = int(factor)
    if factor < 1:
        raise ValueError(f"decimation factor must be >= 1, got {factor}")
    fs_mid = fs / factor
    if factor == 1:
        return ()
    last = _split(factor)
    first = factor // last
    if first == 1:
        return (Decimator.design(fs, factor, f_pass, fs_mid / 2, atten_db),)
    fs1 = fs / first
    stage1 = Decimator.design(fs, first, f_pass, fs1 - fs_mid / 2, atten_db)
    stage2 = Decimator.design(fs1, last, f_pass, fs_mid / 2, atten_db)
    return stage1, stage2


def _split(factor: int) -> int:
    """The second stage's factor: a divisor of `factor` in [8, 64] (1 if there is none)."""
    if factor < 200:
        return factor
    for d in (25, 20, 16, 32, 40, 50, 10, 64, 12, 8, 15, 24, 30, 60):
        if factor % d == 0:
            return d
    return factor


@dataclass(frozen=True, eq=False)
class DecimatorState:
    """Input samples a stage still needs, and where its next output is centred.

    Parameters
    ----------
    buffer : numpy.ndarray, shape (channels, m)
        Input samples from index `start` on (negative indices are the extension before the
        first sample).
    start : int
        Input index of ``buffer[:, 0]``.
    next_centre : int
        Input index the next output is centred on.
    n_in : int
        Inputs consumed so far.
    primed : bool
        True once the start extension exists (it needs the first ``max(half + 1, anchor)``
        samples).
    """

    buffer: np.ndarray
    start: int
    next_centre: int
    n_in: int
    primed: bool = False


def decimator_init(stage: Decimator, n_channels: int) -> DecimatorState:
    """State before the first chunk of a signal with `n_channels` rows.

    Parameters
    ----------
    stage : Decimator
        The stage the state is for.
    n_channels : int
        Rows (channels) of the signal.

    Returns
    -------
    DecimatorState
        The empty state.
    """
    return DecimatorState(np.zeros((n_channels, 0)), 0, 0, 0)


def decimator_step(stage: Decimator, state: DecimatorState,
                   x: np.ndarray) -> tuple[np.ndarray, DecimatorState]:
    """Feed a chunk `x`; return the outputs now complete and the new state.

    Parameters
    ----------
    stage : Decimator
        The stage.
    state : DecimatorState
        State after the previous chunk (:func:`decimator_init` before the first).
    x : numpy.ndarray, shape (channels, n)
        The next input samples.

    Returns
    -------
    y : numpy.ndarray, shape (channels, k)
        The outputs now complete (k may be 0).
    state : DecimatorState
        State for the next chunk.
    """
    x = np.asarray(x, dtype=float)
    n_in = state.n_in + x.shape[1]
    if stage.factor == 1:
        return x, DecimatorState(state.buffer, 0, n_in, n_in, True)
    if state.primed:
        return _advance(stage, state.buffer, x, state.start, state.next_centre, n_in)
    buffer = np.concatenate([state.buffer, x], axis=1)
    if buffer.shape[1] < max(stage.half + 1, stage.anchor):
        return np.zeros((x.shape[0], 0)), DecimatorState(buffer, 0, 0, n_in)
    start_pad = _odd_extension(buffer, stage.half, stage.anchor, at_start=True)
    held = np.concatenate([start_pad, buffer], axis=1)
    return _advance(stage, held, np.zeros((x.shape[0], 0)), -stage.half, 0, n_in)


def decimator_flush(stage: Decimator, state: DecimatorState) -> np.ndarray:
    """Outputs centred on the last inputs, extending the signal past its end.

    Parameters
    ----------
    stage : Decimator
        The stage.
    state : DecimatorState
        State after the last chunk.

    Returns
    -------
    numpy.ndarray, shape (channels, k)
        The remaining outputs, up to the one centred on or before the last input.
    """
    if stage.factor == 1 or state.n_in == 0:
        return np.zeros((state.buffer.shape[0], 0))
    held, start = state.buffer, state.start
    pad = _odd_extension(held, stage.half + stage.factor, stage.anchor, at_start=False)
    if not state.primed:  # a signal shorter than half the filter
        held = np.concatenate([_odd_extension(held, stage.half, stage.anchor, at_start=True),
                               held], axis=1)
        start = -stage.half
    y, _ = _advance(stage, held, pad, start, state.next_centre, state.n_in)
    n_keep = max(0, (state.n_in - 1 - state.next_centre) // stage.factor + 1)
    return y[:, :n_keep]


def _odd_extension(x: np.ndarray, n: int, n_fit: int, at_start: bool) -> np.ndarray:
    """`n` samples continuing `x` (channels, m) beyond its start or end by point reflection,
    ``2 a - x[k]``, as scipy's filtfilt pads: a straight line continues straight, so a slope
    at the ends is not bent by the filter. The centre ``a`` is the end value of a straight line
    fitted to the `n_fit` samples at that end, not the end sample alone, whose scope noise would
    otherwise be doubled into the whole extension. Beyond the available samples the last
    reflected value is repeated."""
    m = x.shape[1]
    k = np.minimum(np.arange(1, n + 1), m - 1)
    w = x[:, :n_fit] if at_start else x[:, max(0, m - n_fit):][:, ::-1]  # edge sample first
    j = np.arange(w.shape[1], dtype=float) - (w.shape[1] - 1) / 2
    anchor = w.mean(axis=1)
    if j.size > 1:  # line through the mean, evaluated at the edge sample j[0]
        anchor = anchor + (w @ j) / (j @ j) * j[0]
    if at_start:
        return (2 * anchor[:, np.newaxis] - x[:, k])[:, ::-1]
    return 2 * anchor[:, np.newaxis] - x[:, m - 1 - k]


def _advance(stage: Decimator, held: np.ndarray, x: np.ndarray, start: int, next_centre: int,
             n_in: int) -> tuple[np.ndarray, DecimatorState]:
    """Outputs over the held samples followed by `x`, without copying `x` (it can be large)."""
    end = start + held.shape[1] + x.shape[1]  # one past the last available input index
    half, factor = stage.half, stage.factor
    n_out = max(0, (end - 1 - half - next_centre) // factor + 1)
    y = _fir_at(np.ascontiguousarray(held), np.ascontiguousarray(x), stage.taps,
                next_centre - half - start, factor, n_out)
    next_centre += n_out * factor
    # Keep what the next window needs, and enough samples for the end reflection and its fit.
    keep_from = min(next_centre - half, end - max(half, stage.anchor)) - start  # in (held, x)
    n_held = held.shape[1]
    if keep_from >= n_held:
        kept = x[:, keep_from - n_held:].copy()  # copy: lets the chunk be freed
    else:
        kept = np.concatenate([held[:, keep_from:], x], axis=1)
    return y, DecimatorState(kept, start + keep_from, next_centre, n_in, True)


@njit(cache=True, nogil=True)
def _fir_at(held, x, taps, first, factor, n_out):
    """``y[c, j] = taps . z[c, first + j factor : ... + L]`` with z = held and x joined."""
    n_ch = x.shape[0]
    n_taps = taps.size
    n_held = held.shape[1]
    y = np.empty((n_ch, n_out))
    window = np.empty(n_taps)
    for c in range(n_ch):
        for j in range(n_out):
            s = first + j * factor
            if s >= n_held:
                y[c, j] = np.dot(taps, x[c, s - n_held:s - n_held + n_taps])
            elif s + n_taps <= n_held:
                y[c, j] = np.dot(taps, held[c, s:s + n_taps])
            else:  # the window straddles the held samples and the new chunk
                # Joined into one window and summed by the same dot product as the others, so
                # an output does not depend on where a chunk border fell (bit for bit).
                m = n_held - s
                window[:m] = held[c, s:]
                window[m:] = x[c, :n_taps - m]
                y[c, j] = np.dot(taps, window)
    return y
