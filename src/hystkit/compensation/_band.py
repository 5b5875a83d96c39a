"""A prediction band on every estimate: conformal, from held-out runs, with a local scale.

Calibration (:func:`._calibration.calibrate_band`) uses the validation folds of ``select``
(:mod:`._folds`): left-out recordings when there are several, interleaved cycles of one
recording otherwise. Each fold's compensator runs on its held-out samples the way it will be
used, and every held-out sample gives a score

    score = max(|position - estimate| - w * o, 0) / sigma

where ``sigma`` is the local scale and ``w * o`` the extrapolation term below. The band at
level ``L`` is ``estimate +- (q_L * sigma + w * o)``, ``q_L`` the ``ceil((n + 1) L) / n``
empirical quantile of the n scores (split conformal prediction normalised by a local scale;
Lei et al. 2018, "Distribution-free predictive inference for regression", sec. 5.2).

The local scale and the extrapolation term use only sensor samples up to now and numbers in
the model file (the band is causal, and a stream reproduces it bit for bit):

- ``rate``: an exponentially weighted mean (time constant ``tau``) of |ds/dt| of the
  normalised sensor. ``sigma = 1 - share + share * rate / rate_reference``: ``share`` is
  fitted on the held-out errors (how much of them grows with the rate; at most
  ``MAX_RATE_SHARE`` so that the band never vanishes at rest), and beyond the fastest rate seen
  in training (``rate_high``, its 99th percentile) ``sigma`` grows in proportion: driven twice
  as fast as ever in training, the band is at least twice as wide.
- ``o``: how far the normalised sensor lies outside the training range, in units of that
  range's width, remembered with the same time constant (a hysteretic model's state stays
  disturbed for a while after an excursion). ``w`` is the training position range [mm]: beyond
  the range, the band grows by the extrapolated distance itself, because nothing in the
  training data says how the model behaves there.

What the validation cannot see the band cannot either: with one recording an offset that
changes between runs is invisible (give several recordings), and behaviour never met in
training (another excitation, a new kind of drift) is covered only through the rate and range
terms. ``hystkit evaluate`` reports the coverage a band achieved on a recording with truth.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from numba import njit

from ..errors import InputError
from ..io import Recording

__all__ = ["BAND_SCORE_KEYS", "DEFAULT_LEVEL", "Band", "BandState", "band_features",
           "feature_decay", "feature_range", "feature_step", "half_width", "interval",
           "interval_scores", "position_width"]

DEFAULT_LEVEL = 0.90
# Probabilities at which the model file keeps the calibration scores' quantiles.
QUANTILE_GRID = np.linspace(0.0, 1.0, 201)
# The share of the scale that may grow with the rate: sigma >= 1 - MAX_RATE_SHARE at rest.
MAX_RATE_SHARE = 0.9
# Time constant of the rate and range memory: this many samples, and at least MIN_TAU_S.
TAU_SAMPLES = 10
MIN_TAU_S = 1.0
# Fewer held-out samples than this cannot calibrate a band at the default level.
MIN_CALIBRATION = 20
BAND_SCORE_KEYS = ("band_level", "band_coverage", "band_width_mean", "band_width_median",
                   "interval_score")


@dataclass(frozen=True)
class Band:
    """A compensator's calibrated prediction band (see the module docstring).

    Parameters
    ----------
    level : float
        The nominal level the band was calibrated for and is used at by default.
    quantiles : tuple of float
        The calibration scores' quantiles [position units] at ``QUANTILE_GRID``.
    n_calibration : int
        Held-out samples the scores come from.
    tau : float
        Time constant [s] of the rate and range memory.
    rate_reference : float
        Mean rate of the normalised sensor in training [1/s].
    rate_high : float
        99th percentile of that rate in training [1/s].
    rate_share : float
        Share of the scale that grows with the rate, in ``[0, MAX_RATE_SHARE]``.
    protocol : str
        The validation protocol the scores come from.
    """

    level: float
    quantiles: tuple[float, ...]
    n_calibration: int
    tau: float
    rate_reference: float
    rate_high: float
    rate_share: float
    protocol: str

    def __post_init__(self) -> None:
        q = np.asarray(self.quantiles, dtype=float)
        if q.shape != QUANTILE_GRID.shape or not np.all(np.isfinite(q)) or np.any(q < 0) \
                or np.any(np.diff(q) < 0):
            raise ValueError(f"band quantiles must be {QUANTILE_GRID.size} finite, non-negative, "
                             f"non-decreasing numbers")
        check_level(self.level)
        if not (isinstance(self.n_calibration, int | np.integer) and self.n_calibration >= 1):
            raise ValueError(f"band n_calibration must be a positive integer, got "
                             f"{self.n_calibration!r}")
        for name in ("tau", "rate_reference", "rate_high"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"band {name} must be finite and positive, got {value!r}")
        if not 0.0 <= self.rate_share <= MAX_RATE_SHARE:
            raise ValueError(f"band rate_share must lie in [0, {MAX_RATE_SHARE}], got "
                             f"{self.rate_share!r}")
        object.__setattr__(self, "quantiles", tuple(float(v) for v in q))
        object.__setattr__(self, "n_calibration", int(self.n_calibration))

    def quantile(self, level: float | None = None) -> float:
        """The score quantile ``q`` [position units] of the band at `level` (default: the
        band's own), with the finite-sample correction of split conformal prediction."""
        level = self.level if level is None else check_level(level)
        n = self.n_calibration
        p = min(1.0, math.ceil((n + 1) * level) / n)
        return float(np.interp(p, QUANTILE_GRID, self.quantiles))

    def to_dict(self) -> dict:
        return {**asdict(self), "quantiles": list(self.quantiles)}

    @classmethod
    def from_dict(cls, d: dict) -> Band:
        names = set(cls.__dataclass_fields__)
        if set(d) != names:
            missing, extra = sorted(names - set(d)), sorted(set(d) - names)
            raise ValueError(f"band needs the keys {', '.join(sorted(names))}"
                             + (f"; missing {', '.join(missing)}" if missing else "")
                             + (f"; unknown {', '.join(extra)}" if extra else ""))
        return cls(**{**d, "quantiles": tuple(d["quantiles"])})


def check_level(level: float) -> float:
    """`level` if it is a probability strictly between 0 and 1, else ValueError."""
    if not (isinstance(level, int | float | np.floating) and 0.0 < level < 1.0):
        raise ValueError(f"band level must lie strictly between 0 and 1, got {level!r}")
    return float(level)


@dataclass(frozen=True)
class BandState:
    """What the band's features remember between samples (a stream carries it).

    Parameters
    ----------
    started : bool
        A sample has been seen (the first sample has no rate).
    previous : float
        The last normalised sensor sample.
    rate : float
        The rate's running mean [1/s].
    outside : float
        The remembered distance outside the training range [range widths].
    """

    started: bool = False
    previous: float = 0.0
    rate: float = 0.0
    outside: float = 0.0


@njit(cache=True, inline="always")
def feature_step(v, started, previous, r, o, dt, decay, low, high, width):  # pragma: no cover
    """One sample of :func:`band_features`: the rate and range memory after normalised sensor
    sample `v` (compiled, inlined by the live stream's kernel, so both give the same bits).

    Parameters
    ----------
    v : float
        The normalised sensor sample.
    started : float
        1.0 once a sample has been seen (the first has no rate), else 0.0.
    previous : float
        The previous normalised sample.
    r, o : float
        The rate's running mean [1/s] and the remembered excursion [range widths] before `v`.
    dt : float
        Sample time [s].
    decay : float
        The memory's factor per sample (:func:`feature_decay`).
    low, high : float
        The range the excursion is measured from (:func:`feature_range`).
    width : float
        ``high - low``.

    Returns
    -------
    r, o : float
        The rate's running mean and the remembered excursion after `v`.
    """
    d = abs(v - previous) / dt if started > 0.0 else 0.0
    r = decay * r + (1.0 - decay) * d
    beyond = max(low - v, v - high, 0.0) / width
    o = max(beyond, decay * o)
    return r, o


@njit(cache=True)
def _features_kernel(s, dt, decay, low, high, state):  # pragma: no cover - compiled
    n = s.size
    rate = np.empty(n)
    outside = np.empty(n)
    started, previous, r, o = state[0], state[1], state[2], state[3]
    width = high - low
    for k in range(n):
        v = s[k]
        r, o = feature_step(v, started, previous, r, o, dt, decay, low, high, width)
        rate[k] = r
        outside[k] = o
        previous = v
        started = 1.0
    return rate, outside, np.array([started, previous, r, o])


def band_features(s: np.ndarray, dt: float, tau: float, training_range: tuple[float, float],
                  state: BandState | None = None) -> tuple[np.ndarray, np.ndarray, BandState]:
    """Rate and remembered range excursion of the normalised sensor, sample by sample.

    Parameters
    ----------
    s : numpy.ndarray, shape (n,)
        Normalised sensor samples (:meth:`Compensator.normalised_sensor`).
    dt : float
        Sample time [s].
    tau : float
        Time constant [s] of the memory.
    training_range : tuple of float
        The normalised sensor range seen in training.
    state : BandState, optional
        Where an earlier chunk left off; None: the start of a recording.

    Returns
    -------
    rate : numpy.ndarray
        Running mean of |ds/dt| [1/s].
    outside : numpy.ndarray
        Remembered distance outside the training range [range widths].
    state : BandState
        Where this chunk leaves off: the next chunk continues from it exactly.
    """
    state = state or BandState()
    low, high = feature_range(training_range)
    start = np.array([float(state.started), state.previous, state.rate, state.outside])
    rate, outside, end = _features_kernel(np.ascontiguousarray(s, dtype=np.float64), float(dt),
                                          feature_decay(dt, tau), low, high, start)
    return rate, outside, BandState(bool(end[0]), float(end[1]), float(end[2]), float(end[3]))


def feature_range(training_range: tuple[float, float]) -> tuple[float, float]:
    """The range the excursion is measured from: the training range, or for a range of one
    value the unit range above it (distances in its units).

    Parameters
    ----------
    training_range : tuple of float
        The normalised sensor range seen in training.

    Returns
    -------
    low, high : float
        The range, ``high > low``.
    """
    low, high = training_range
    return float(low), float(high if high > low else low + 1.0)


def feature_decay(dt: float, tau: float) -> float:
    """The memory's factor per sample.

    Parameters
    ----------
    dt : float
        Sample time [s].
    tau : float
        Time constant [s] of the memory.

    Returns
    -------
    float
        ``exp(-dt / tau)``.
    """
    return math.exp(-dt / tau)


def local_scale(band: Band, rate: np.ndarray) -> np.ndarray:
    """The scale ``sigma`` of the module docstring, per sample (1 at the reference rate)."""
    return rate_scale(rate, band.rate_share, band.rate_reference, band.rate_high)


def rate_scale(rate: np.ndarray, share: float, reference: float, high: float) -> np.ndarray:
    """``sigma`` from its three numbers (:func:`local_scale`; the calibration needs it before
    the band exists)."""
    return 1.0 - share + share * rate / reference + np.maximum(rate / high - 1.0, 0.0)


def half_width(band: Band, quantile: float, rate: np.ndarray, outside: np.ndarray,
               position_width: float) -> np.ndarray:
    """The band's half-width [position units] per sample.

    Parameters
    ----------
    band : Band
        The calibrated band.
    quantile : float
        ``band.quantile(level)`` (a stream computes it once).
    rate, outside : numpy.ndarray, shape (n,)
        The features of :func:`band_features`.
    position_width : float
        The training position range's width (:func:`position_width`).

    Returns
    -------
    numpy.ndarray, shape (n,)
        ``quantile * sigma(rate) + position_width * outside``.
    """
    return quantile * local_scale(band, rate) + position_width * outside


def position_width(comp) -> float:
    """The training position range's width [mm] (the extrapolation term's unit).

    Parameters
    ----------
    comp : Compensator
        Whose ``position_range`` (the training positions' ``(low, high)`` [mm]) is read.

    Returns
    -------
    float
        ``high - low``.
    """
    lo, hi = comp.position_range
    return float(hi - lo)


def interval(comp, recording: Recording, estimate: np.ndarray,
             level: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper band [mm] around `estimate`, the compensator's estimate on
    `recording` (:meth:`Compensator.estimate`).

    Parameters
    ----------
    comp : Compensator
        A compensator with a band.
    recording : Recording
        The recording the estimate was made on.
    estimate : numpy.ndarray
        The estimate [mm].
    level : float, optional
        Nominal coverage; default the band's.

    Returns
    -------
    lower, upper : numpy.ndarray
    """
    band = comp.band
    if band is None:
        raise InputError(f"the {comp.model} compensator{comp._from()} has no band (fitted "
                         f"without one, or by a hystkit before bands); fit it again")
    s = comp.normalised_sensor(recording.sensor)
    rate, outside, _ = band_features(s, comp.structure.dt, band.tau, comp.training_range)
    h = half_width(band, band.quantile(level), rate, outside, position_width(comp))
    return estimate - h, estimate + h


def interval_scores(position: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                    level: float) -> dict:
    """How a band did against the truth: coverage, widths and the interval score.

    Parameters
    ----------
    position : numpy.ndarray
        The true position [mm].
    lower, upper : numpy.ndarray
        The band [mm].
    level : float
        Its nominal level.

    Returns
    -------
    dict
        ``band_level``, ``band_coverage`` (share of samples inside), ``band_width_mean`` and
        ``band_width_median`` [mm], ``interval_score`` [mm] (Gneiting & Raftery 2007, eq. 43:
        width plus 2 / (1 - level) times the miss; lower is better).
    """
    alpha = 1.0 - level
    width = upper - lower
    below, above = np.maximum(lower - position, 0.0), np.maximum(position - upper, 0.0)
    return {"band_level": float(level),
            "band_coverage": float(np.mean((position >= lower) & (position <= upper))),
            "band_width_mean": float(np.mean(width)),
            "band_width_median": float(np.median(width)),
            "interval_score": float(np.mean(width + 2.0 / alpha * (below + above)))}
