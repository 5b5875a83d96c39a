"""Spectra for choosing the Butterworth cut-off (sec. 4.3.1, fig. 4.10, eq. 4.1).

The document looks at the spectrum of each gauge and picks "a minimum cut-off frequency
f_c,min >~ 8 Hz ... so that the higher harmonics are included up to the point that the
magnitude of the highest harmonic is buried under the signal noise", then "conservatively"
f_c = 20 Hz. Here that reading is a rule with numbers (:class:`CutoffRule`):

* PSD: Welch (Hann window, segments of ``segment_s`` seconds, 50 % overlap), one-sided, of
  dR/R of each gauge and of the differential signal dR1/R1 - dR2/R2 [1/Hz];
* local noise floor N(f): the running median of the differential PSD over ``floor_width_hz``
  (lines narrower than half the window do not move it), divided by the median-to-mean ratio
  of the Welch estimate (chi-square with nu = 2 K / 1.056 degrees of freedom for K segments,
  Hann, 50 % overlap), so that N(f) estimates the noise *density*;
* f_signal: the peak of the highest line (below ``f_search_max``) whose differential PSD
  exceeds ``10**(margin_db / 10) * N(f)``: the highest harmonic not yet buried in the noise,
  the document's f_c,min;
* suggested cut-off ``f_c = safety * f_signal`` (safety 2.5 = the document's 20 Hz / 8 Hz), at
  which the zero-phase 2nd-order filter passes f_signal with amplitude
  ``|H|^2 = 1 / (1 + (1/2.5)^4) = 0.975`` (-0.22 dB).

A raw recording is first brought to gauge resistances at the scope rate (eq. 4.3, with the
measured supply ``v0`` when asked) and decimated to about ``fs_analysis`` (1 kHz) by the same
streaming FIR stages as preprocessing, flat to 0.4 of that rate; dR/R follows eq. 4.4-4.5.

The proposed filter's response is computed with ``scipy.signal.sosfreqz`` on the designed
second-order sections; the zero-phase (forward-backward) filter's amplitude response is
``|H|^2`` and its power response ``|H|^4``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy import ndimage, signal, stats

from ._filters import butterworth_sections

__all__ = ["CutoffRule", "Spectrum", "butterworth_response", "noise_floor", "spectrum",
           "welch_psd"]

# Welch with a Hann window and 50 % overlap: adjacent segments correlate with c = 0.167, so
# the estimate has nu = 2 K / (1 + 2 c^2) = 2 K / 1.056 degrees of freedom (Welch 1967).
_HANN_HALF_OVERLAP = 1.0 + 2 * 0.167 ** 2


@dataclass(frozen=True)
class CutoffRule:
    """How :func:`spectrum` suggests a cut-off (see the module docstring).

    Parameters
    ----------
    margin_db : float
        A line counts as signal when it stands this far above the local noise floor [dB].
    safety : float
        Suggested cut-off = safety * f_signal (2.5: the document's 20 Hz over its 8 Hz).
    floor_width_hz : float
        Width of the running median that gives the local noise floor [Hz].
    order : int
        One-way Butterworth order of the proposed filter (2 in eq. 4.1).
    """

    margin_db: float = 10.0
    safety: float = 2.5
    floor_width_hz: float = 4.0
    order: int = 2

    def __post_init__(self) -> None:
        if not (self.margin_db > 0 and self.safety >= 1 and self.floor_width_hz > 0
                and 1 <= self.order <= 10):
            raise ValueError("margin_db and floor_width_hz must be > 0, safety >= 1 and order "
                             f"in [1, 10]; got {self}")

    def text(self) -> str:
        """The rule in one sentence, with its numbers."""
        return (f"f_signal = peak of the highest line where the differential PSD exceeds "
                f"{self.margin_db:g} dB over the local noise floor (running median over "
                f"{self.floor_width_hz:g} Hz, corrected to the mean density); suggested cut-off "
                f"f_c = {self.safety:g} x f_signal, for a zero-phase order-{self.order} "
                "Butterworth")


@dataclass(frozen=True, eq=False)
class Spectrum:
    """Output of :func:`spectrum`.

    Parameters
    ----------
    freq : numpy.ndarray, shape (m,)
        Frequencies [Hz].
    psd : dict of str to numpy.ndarray
        Name -> one-sided PSD [1/Hz] on `freq` (``dr1``, ``dr2`` when the gauges are known,
        ``differential`` always).
    floor : numpy.ndarray, shape (m,)
        The differential's local noise floor [1/Hz].
    f_signal, cutoff : float
        The rule's highest signal line and suggested cut-off [Hz]; NaN when no line stands
        above the margin (a broadband signal or noise: ``summary["no_line"]`` says why).
    response : dict of str to numpy.ndarray
        Cut-off label -> zero-phase amplitude response ``|H|^2`` on `freq` (the suggested
        cut-off's only when there is one).
    rule : CutoffRule
        The rule applied.
    fs : float
        Sample rate of the analysed signals [Hz].
    summary : dict
        Plain numbers for JSON.
    """

    freq: np.ndarray
    psd: dict[str, np.ndarray]
    floor: np.ndarray
    f_signal: float
    cutoff: float
    response: dict[str, np.ndarray]
    rule: CutoffRule
    fs: float
    summary: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """Everything as plain numbers and lists (the JSON of ``hystkit spectrum``)."""
        return {**self.summary, "rule": {**asdict(self.rule), "text": self.rule.text()},
                "freq_hz": self.freq, "psd_per_hz": self.psd, "noise_floor_per_hz": self.floor,
                "filter_amplitude_response": self.response}

    def plot(self, title: str = ""):
        """PSDs, floor and threshold on log axes; the filters' zero-phase response (dB) on a
        second axis; f_signal and the cut-offs marked. Returns the Figure."""
        from ._spectrum_plot import plot_spectrum  # matplotlib: only when a figure is asked for

        return plot_spectrum(self, title)


def welch_psd(x: np.ndarray, fs: float, segment_s: float) -> tuple[np.ndarray, np.ndarray, int]:
    """One-sided Welch PSD [unit²/Hz] of the rows of `x` (Hann, 50 % overlap, mean removed).

    Parameters
    ----------
    x : numpy.ndarray, shape (..., n)
        Signal(s), samples along the last axis.
    fs : float
        Sample rate [Hz].
    segment_s : float
        Segment length [s] (at least 8 samples, at most the whole signal).

    Returns
    -------
    freq : ndarray [Hz]
    psd : ndarray, shape (..., freq.size)
    n_segments : int
        Segments averaged (K), which sets the estimate's spread.
    """
    n = np.shape(x)[-1]
    nperseg = min(n, max(8, round(segment_s * fs)))
    freq, psd = signal.welch(x, fs=fs, window="hann", nperseg=nperseg, noverlap=nperseg // 2,
                             detrend="constant", scaling="density", axis=-1)
    n_segments = 1 + (n - nperseg) // (nperseg - nperseg // 2)
    return freq, psd, n_segments


def noise_floor(psd: np.ndarray, df: float, width_hz: float, n_segments: int) -> np.ndarray:
    """Local noise density [unit²/Hz]: running median of `psd` over `width_hz`, corrected.

    The running median is divided by the median of a chi-square with nu = 2 K / 1.056 degrees
    of freedom over nu (the median of a Welch estimate of white noise lies below its mean by
    that ratio).

    Parameters
    ----------
    psd : numpy.ndarray, shape (m,)
        Welch PSD [unit²/Hz] on bins `df` apart.
    df : float
        Bin spacing [Hz].
    width_hz : float
        Width of the running median [Hz] (at least 3 bins).
    n_segments : int
        Segments K the Welch estimate averaged.

    Returns
    -------
    numpy.ndarray, shape (m,)
        The noise floor N(f) [unit²/Hz].
    """
    size = max(3, 2 * round(0.5 * width_hz / df) + 1)
    nu = 2 * n_segments / _HANN_HALF_OVERLAP
    return ndimage.median_filter(psd, size=size, mode="nearest") / (stats.chi2.median(nu) / nu)


def butterworth_response(freq: np.ndarray, fs: float, cutoff: float, order: int = 2
                         ) -> np.ndarray:
    """Amplitude response ``|H(f)|^2`` of the zero-phase Butterworth of eq. 4.1.

    The forward-backward filter that ``lowpass_zero_phase`` applies, from ``sosfreqz`` of the
    designed sections.

    Parameters
    ----------
    freq : numpy.ndarray
        Frequencies [Hz].
    fs : float
        Sample rate [Hz].
    cutoff : float
        -3 dB frequency of the one-way filter [Hz].
    order : int
        One-way order.

    Returns
    -------
    numpy.ndarray
        ``|H|^2`` [-] at `freq`.

    Raises
    ------
    ValueError
        If `cutoff` is not between 0 and ``fs / 2``.
    """
    sos = butterworth_sections(fs, cutoff, order)
    _, h = signal.sosfreqz(sos, worN=np.asarray(freq, dtype=float), fs=fs)
    return np.abs(h) ** 2


def spectrum(rows: dict[str, np.ndarray], fs: float, *, segment_s: float | None = None,
             rule: CutoffRule | None = None, compare_cutoff: float | None = 20.0,
             f_search_max: float | None = None) -> Spectrum:
    """Welch PSDs, local noise floor and the suggested cut-off of dR/R signals.

    Parameters
    ----------
    rows : dict
        ``differential`` (dR1/R1 - dR2/R2 [-]) and optionally ``dr1``, ``dr2``, sampled at `fs`.
    fs : float
        Sample rate [Hz].
    segment_s : float, optional
        Welch segment length [s] (bins 1 / segment_s apart, Hann main lobe 4 bins wide).
        Default: 20 s, or half the recording when shorter (at least 3 segments).
    rule : CutoffRule, optional
    compare_cutoff : float, optional
        A second cut-off [Hz] whose response is overlaid and summarised (the document's 20 Hz).
    f_search_max : float, optional
        Lines are searched below this [Hz] (default 0.4 fs, where decimation filters are flat).

    Returns
    -------
    Spectrum
        PSDs, noise floor, f_signal, the suggested cut-off and the filters' responses. When no
        line stands `margin_db` above the floor (a broadband signal, pure noise or a flat
        signal) f_signal and the cut-off are NaN and ``summary["no_line"]`` says why: the
        spectrum is still shown, there is no line to pick a cut-off from.

    Raises
    ------
    ValueError
        Fewer than 3 segments (one or two leave single noise bins a few percent likely to pass
        10 dB over the floor), or the suggested cut-off is not below fs / 2.
    """
    rule = CutoffRule() if rule is None else rule
    names = [k for k in ("dr1", "dr2", "differential") if k in rows]
    duration = np.shape(rows["differential"])[-1] / fs
    segment_s = min(20.0, duration / 2) if segment_s is None else segment_s
    freq, psd, n_seg = welch_psd(np.vstack([rows[k] for k in names]), fs, segment_s)
    if n_seg < 3:
        raise ValueError(f"{n_seg} Welch segment(s) of {segment_s:g} s in {duration:.6g} s: too "
                         "few for the noise floor; use segments of at most half the recording")
    df = float(freq[1] - freq[0])
    diff = psd[-1]
    floor = noise_floor(diff, df, rule.floor_width_hz, n_seg)
    f_max = 0.4 * fs if f_search_max is None else min(f_search_max, 0.5 * fs)
    # Above the second bin: the first bins hold what is left of the mean and the drift.
    search = (freq >= 2 * df) & (freq <= f_max)
    above = search & (diff > floor * 10 ** (rule.margin_db / 10))
    no_line = None
    if above.any():
        f_signal = float(freq[_last_line_peak(above, diff)])
    else:  # a broadband signal (or pure noise): the spectrum, but no cut-off to suggest
        f_signal = math.nan
        no_line = (f"no spectral line stands {rule.margin_db:g} dB above the noise floor "
                   f"between {2 * df:.3g} and {f_max:.3g} Hz, so there is no line to pick a "
                   f"cut-off from: " + _why_no_line(duration, df, rule.floor_width_hz))
    cutoff = rule.safety * f_signal
    if not cutoff < fs / 2 and no_line is None:
        raise ValueError(f"suggested cut-off {cutoff:.3g} Hz is not below fs/2 = {fs / 2:.3g} Hz: "
                         "the signal reaches the top of the analysed band (analyse the raw file "
                         "at a higher rate)")
    cutoffs, compare_skipped = ({} if no_line else {"suggested": cutoff}), None
    # fs from time stamps can be 40.000000001 Hz: a 20 Hz comparison would sit at Nyquist.
    if compare_cutoff is not None and compare_cutoff != cutoff:
        if compare_cutoff < 0.5 * fs * (1 - 1e-6):
            cutoffs["compare"] = float(compare_cutoff)
        else:
            compare_skipped = (f"{compare_cutoff:g} Hz comparison skipped: at or above fs/2 = "
                               f"{fs / 2:.4g} Hz")
    response = {f"{value:.3g} Hz ({key})": butterworth_response(freq, fs, value, rule.order)
                for key, value in cutoffs.items()}
    summary = {
        "fs_hz": fs, "n_samples": int(np.shape(rows["differential"])[-1]),
        "segment_s": (2 * (freq.size - 1)) / fs, "n_segments": n_seg, "resolution_hz": df,
        "f_signal_hz": None if no_line else f_signal,
        "suggested_cutoff_hz": None if no_line else cutoff,
        "noise_floor_at_f_signal_per_hz": (None if no_line
                                           else float(np.interp(f_signal, freq, floor))),
        "filters": {} if no_line else {
            key: _filter_summary(freq, fs, value, rule.order, f_signal, floor)
            for key, value in cutoffs.items()},
        "compare_skipped": compare_skipped, "no_line": no_line,
    }
    return Spectrum(freq=freq, psd=dict(zip(names, psd, strict=True)), floor=floor,
                    f_signal=f_signal, cutoff=cutoff, response=response, rule=rule, fs=fs,
                    summary=summary)


# A running median over fewer bins than this is filled by the harmonics of a short record.
_FEW_FLOOR_BINS = 20


def _why_no_line(duration: float, df: float, floor_width_hz: float) -> str:
    """The likely cause of finding no line: a record too short to resolve it, or no signal."""
    bins = floor_width_hz / df
    if bins >= _FEW_FLOOR_BINS:
        return "the signal is a band, not lines (a broadband excitation), pure noise or flat"
    return (f"the record is short ({duration:.3g} s, frequency resolution {df:.2g} Hz): a "
            f"fundamental below {2 * df:.2g} Hz is outside the search, and the "
            f"{floor_width_hz:g} Hz running median spans only {bins:.0f} bins, which the "
            f"harmonics fill (or the signal is pure noise); a record of "
            f"{2 * _FEW_FLOOR_BINS / floor_width_hz:.3g} s or more gives segments long enough")


def _last_line_peak(above: np.ndarray, psd: np.ndarray) -> int:
    """Bin of the highest PSD within the last run of consecutive bins above the threshold: the
    centre of the highest line, not the edge of its window main lobe."""
    last = int(np.flatnonzero(above)[-1])
    first = last
    while first > 0 and above[first - 1]:
        first -= 1
    return first + int(np.argmax(psd[first:last + 1]))


def _filter_summary(freq: np.ndarray, fs: float, cutoff: float, order: int, f_signal: float,
                    floor: np.ndarray) -> dict:
    """What a cut-off costs and gains: the zero-phase gain at f_signal and the RMS of the noise
    floor above f_signal (the band the cut-off decides on) with and without the filter,
    sqrt(integral of N(f) |H|^4 df) (the power response is |H|^4)."""
    h2 = butterworth_response(freq, fs, cutoff, order)
    at_signal = float(butterworth_response(np.array([f_signal]), fs, cutoff, order)[0])
    band = freq >= f_signal
    passed = math.sqrt(float(np.trapezoid(floor[band] * h2[band] ** 2, freq[band])))
    return {"cutoff_hz": cutoff, "gain_at_f_signal_db": 20 * math.log10(at_signal),
            "noise_rms_above_f_signal_passed": passed,
            "noise_rms_above_f_signal_unfiltered":
                math.sqrt(float(np.trapezoid(floor[band], freq[band])))}
