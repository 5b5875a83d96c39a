"""Position excitations of the document's experiments (sec. 4.3, paper 9.2 sec. III), in mm."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._docfill import docfiller

__all__ = [
    "EXPERIMENTS",
    "Experiment",
    "decaying_sine",
    "excitation",
    "exponential_chirp",
    "filtered_noise",
    "sine",
]

# What the excitations of time take and return (%(t)s, %(amplitude)s, %(position)s).
EXCITATION_ENTRIES = {
    "t": """t : numpy.ndarray
    Times [s].""",
    "amplitude": """amplitude : float, default 3.0
    Amplitude [mm].""",
    "position": """Returns
-------
numpy.ndarray
    Position [mm], same shape as `t`.""",
}
fill_excitation_doc = docfiller(EXCITATION_ENTRIES.__getitem__)


@fill_excitation_doc
def sine(t: np.ndarray, frequency: float = 0.5, amplitude: float = 3.0) -> np.ndarray:
    """``amplitude * sin(2 pi f t)`` [mm]; the sine experiment is 0.5 Hz, 3 mm (eq. 9.14).

    Parameters
    ----------
    %(t)s
    frequency : float, default 0.5
        Frequency [Hz].
    %(amplitude)s

    %(position)s
    """
    return amplitude * np.sin(2 * np.pi * frequency * np.asarray(t, dtype=float))


@fill_excitation_doc
def decaying_sine(t: np.ndarray, frequency: float = 0.5, start_amplitude: float = 2.0,
                  end_amplitude: float = 0.1, duration: float = 200.0) -> np.ndarray:
    """Sine whose amplitude falls exponentially from ``start`` to ``end`` over ``duration`` [mm].

    The document's decay experiment: 0.5 Hz, 2 mm to 100 um over 200 s; its shrinking cycles are
    minor loops inside the first, major one.

    Parameters
    ----------
    %(t)s
    frequency : float, default 0.5
        Frequency [Hz].
    start_amplitude, end_amplitude : float, default 2.0 and 0.1
        Amplitude [mm] at ``t = 0`` and ``t = duration``.
    duration : float, default 200.0
        Time [s] over which the amplitude falls from start to end.

    %(position)s
    """
    t = np.asarray(t, dtype=float)
    envelope = start_amplitude * (end_amplitude / start_amplitude) ** (t / duration)
    return envelope * np.sin(2 * np.pi * frequency * t)


@fill_excitation_doc
def exponential_chirp(t: np.ndarray, f0: float = 0.1, f1: float = 3.0, duration: float = 100.0,
                      amplitude: float = 3.0) -> np.ndarray:
    """Sine sweep whose frequency rises exponentially from ``f0`` to ``f1`` over ``duration``.

    Parameters
    ----------
    %(t)s
    f0, f1 : float, default 0.1 and 3.0
        Start and end frequency [Hz].
    duration : float, default 100.0
        Time [s] at which the frequency reaches `f1`.
    %(amplitude)s

    %(position)s
    """
    from scipy import signal  # here, not at the top: listing the experiments stays light

    return amplitude * signal.chirp(np.asarray(t, dtype=float), f0=f0, t1=duration, f1=f1,
                                    method="logarithmic", phi=-90)


def _fir_lowpass(fs: float, cutoff_3db: float, numtaps: int) -> np.ndarray:
    """Windowed-sinc FIR whose gain is -3 dB at ``cutoff_3db``.

    ``firwin``'s cut-off is the -6 dB point, so the design cut-off is solved for the stated
    -3 dB point, as the document specifies its filter by it.
    """
    from scipy import optimize, signal  # here: as in exponential_chirp

    def gain_error(fc: float) -> float:
        taps = signal.firwin(numtaps, fc, fs=fs)
        _, h = signal.freqz(taps, worN=[cutoff_3db], fs=fs)
        return abs(h[0]) - 1 / np.sqrt(2)

    fc = optimize.brentq(gain_error, cutoff_3db, min(4 * cutoff_3db, 0.49 * fs), xtol=1e-6)
    return signal.firwin(numtaps, fc, fs=fs)


@fill_excitation_doc
def filtered_noise(t: np.ndarray, seed: int, cutoff: float = 4.0, order: int = 500,
                   amplitude: float = 3.0) -> np.ndarray:
    """Gaussian noise through an ``order``-th order FIR low-pass (-3 dB at ``cutoff``) [mm].

    Scaled so that max |x| equals ``amplitude``. The filter's start-up transient is discarded by
    generating ``order`` extra samples first.

    Parameters
    ----------
    t : numpy.ndarray
        Evenly spaced times [s].
    seed : int
        Seed of the noise generator.
    cutoff : float, default 4.0
        -3 dB frequency [Hz] of the low-pass.
    order : int, default 500
        Order of the FIR filter.
    amplitude : float, default 3.0
        Largest absolute value [mm].

    %(position)s
    """
    from scipy import signal  # here: as in exponential_chirp

    t = np.asarray(t, dtype=float)
    fs = 1.0 / np.median(np.diff(t))
    taps = _fir_lowpass(fs, cutoff, order + 1)
    white = np.random.default_rng(seed).standard_normal(t.size + order)
    x = signal.lfilter(taps, 1.0, white)[order:]
    return amplitude * x / np.max(np.abs(x))


@dataclass(frozen=True)
class Experiment:
    """One of the document's excitation experiments: its duration and its trajectory.

    Parameters
    ----------
    name : str
        Experiment name (``sine``, ``chirp``, ...).
    duration : float
        Length [s].
    description : str
        One line for listings.
    trajectory : callable
        ``trajectory(t, seed) -> position`` [mm] for times `t` [s].
    """

    name: str
    duration: float  # s
    description: str
    trajectory: Callable[[np.ndarray, int], np.ndarray]


EXPERIMENTS: dict[str, Experiment] = {
    "sine": Experiment("sine", 200.0, "sine 0.5 Hz, 3 mm", lambda t, seed: sine(t)),
    "decay": Experiment("decay", 200.0, "0.5 Hz sine, 2 mm -> 100 um exponentially over 200 s",
                        lambda t, seed: decaying_sine(t)),
    "chirp": Experiment("chirp", 100.0, "exponential chirp 0.1 -> 3 Hz over 100 s, 3 mm",
                        lambda t, seed: exponential_chirp(t)),
    "noise": Experiment("noise", 200.0, "Gaussian noise, 500th-order FIR low-pass -3 dB at 4 Hz, "
                        "peak 3 mm", lambda t, seed: filtered_noise(t, seed)),
}


def excitation(name: str, fs: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Time [s] and position [mm] of experiment ``name`` sampled at ``fs`` [Hz].

    Parameters
    ----------
    name : str
        A key of :data:`EXPERIMENTS`.
    fs : float
        Sample rate [Hz].
    seed : int, default 0
        Seed of the random experiments (noise).

    Returns
    -------
    t : numpy.ndarray
        Time [s], ``round(duration * fs)`` samples from 0.
    position : numpy.ndarray
        Position [mm].

    Raises
    ------
    ValueError
        An unknown experiment name.
    """
    if name not in EXPERIMENTS:
        raise ValueError(f"unknown excitation {name!r}; choose one of {sorted(EXPERIMENTS)}")
    exp = EXPERIMENTS[name]
    t = np.arange(round(exp.duration * fs)) / fs
    return t, exp.trajectory(t, seed)
