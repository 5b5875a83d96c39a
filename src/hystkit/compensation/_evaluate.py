"""Scores of a compensator on a recording (sec. 5.3.3-5.3.6): the numbers of table 5.5.

Every score comes twice: the *deployable* one, with the compensator's own centring (the
estimate at sample k uses sensor samples <= k and the model file), and the *oracle* one with
the paper's protocol (``recording`` centring: the recording's own sensor mean is removed and its
true mean position added back), which a compensator in use can never have.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..io import Recording
from ..metrics import e_max_pct, e_rms_pct, loop_area, r2, sinad_db
from ._band import BAND_SCORE_KEYS, interval, interval_scores
from ._centring import ORACLE_CENTER, center_label
from ._compensator import POSITION_MARGIN, SENSOR_MARGIN, Compensator
from ._training_checks import MIN_SAMPLES
from ._verdict import FAR_MARGIN

__all__ = ["MIN_SCORED_SAMPLES", "SCORE_KEYS", "evaluate", "use_flags"]

# Scores of fewer samples than a fit needs say nothing (R² of 2 points, a loop of 3): refused.
# Compensating a short recording is fine (each estimate depends on past samples only).
MIN_SCORED_SAMPLES = MIN_SAMPLES

SCORE_KEYS = ("r2", "e_rms_pct", "e_max_pct", "sinad_db", "loop_area")


def use_flags(compensator: Compensator, recording: Recording,
              estimate: np.ndarray) -> dict[str, np.ndarray | None]:
    """Per-sample use-time guards: sensor outside the training range, estimate outside the
    training position range (margins ``SENSOR_MARGIN`` / ``POSITION_MARGIN``).

    Parameters
    ----------
    compensator : Compensator
        The fitted compensator.
    recording : Recording
        The recording the estimate was made from.
    estimate : numpy.ndarray, shape (n,)
        The compensator's estimate [mm].

    Returns
    -------
    dict
        ``sensor_outside`` and ``estimate_outside``: boolean masks, shape (n,), or None when the
        model file does not know the range.
    """
    return {"sensor_outside": compensator.sensor_outside(recording),
            "estimate_outside": compensator.estimate_outside(estimate)}


def _scores(position: np.ndarray, guess: np.ndarray, scale: float,
            fs: float) -> tuple[dict, dict]:
    """The scores of one estimate, and why any of them is undefined (by key)."""
    sinad, sinad_note = _sinad_or_none(guess, fs)
    scores = {"r2": _r2_or_none(position, guess),
              "e_rms_pct": e_rms_pct(position, guess, scale=scale),
              "e_max_pct": e_max_pct(position, guess, scale=scale),
              "sinad_db": sinad, "loop_area": _loop_area_or_none(position, guess)}
    return scores, ({} if sinad_note is None else {"sinad_db": sinad_note})


def evaluate(compensator: Compensator, recording: Recording, *,
             rest_position: float | None = None, level: float | None = None) -> dict:
    """Compare the compensated and the straight-line position with the measured one.

    Errors in per cent are relative to the fitting data's max |position| (eq. 5.10-5.11).
    ``loop_area`` is the normalised loop area (eq. 5.15) of the estimate against the measured
    position (0 for a perfect compensator); ``sensor_loop_area`` is that of the raw sensor.

    Parameters
    ----------
    compensator : Compensator
        The fitted compensator.
    recording : Recording
        A recording with a position column.
    rest_position : float, optional
        Where the device rests during the tare window [mm], if not where it rested in
        training; used only by the ``tare`` centring.
    level : float, optional
        Nominal level of the prediction band scored; default the band's own.

    Returns
    -------
    dict
        ``r2, e_rms_pct, e_max_pct, sinad_db, loop_area`` of the compensator with its own
        (deployable, unless it was fitted with the oracle) centring, named in ``center``; the same
        with a ``linear_`` prefix for the straight line; the same with an ``_oracle`` suffix
        under the paper's protocol (``center_oracle``); ``sensor_loop_area``, ``n_samples``,
        ``extrapolated_fraction``, ``n_sensor_outside`` / ``n_estimate_outside`` (use-time
        guards, None if the model file predates them) with their margins, and
        ``n_sensor_far_outside`` / ``n_estimate_far_outside`` beyond ``far_margin`` of the
        ranges' widths (what :func:`~._verdict.verdict` judges as extrapolation). Every number is
        finite; a score that is undefined or overflowed is None. ``notes``: why a score is
        None, by its key, where there is a reason to give (e.g. ``sinad_db``: the recording
        is too short for its fundamental, and how many samples it needs); empty otherwise.
        With a band (:mod:`._band`): ``band_level``, ``band_coverage``, ``band_width_mean``,
        ``band_width_median`` and ``interval_score`` (deployable: the band uses the sensor up
        to each sample and the model file); without one these are None.

    Raises
    ------
    InputError
        No position column, or fewer than ``MIN_SCORED_SAMPLES`` samples.
    """
    if not recording.has_position():
        raise InputError(f"{recording.source}: column 'position' is needed to evaluate")
    if recording.n_samples < MIN_SCORED_SAMPLES:
        raise InputError(f"{recording.source}: {recording.n_samples} samples; scores need at "
                         f"least {MIN_SCORED_SAMPLES} (as many as a fit)")
    position, scale = recording.position, compensator.scaling.position_scale
    scores = {"n_samples": recording.n_samples, "center": center_label(compensator.center),
              "center_oracle": center_label(ORACLE_CENTER)}
    runs = (("", compensator), ("_oracle", compensator.oracle()))
    estimate, notes = None, {}
    for suffix, comp in runs:
        mean = float(np.mean(position)) if comp.center == ORACLE_CENTER else None
        guess = comp.estimate(recording, mean, rest_position=rest_position)
        line = comp.estimate_linear(recording, mean, rest_position=rest_position)
        estimate = guess if estimate is None else estimate
        for prefix, values in (("", guess), ("linear_", line)):
            # a score that overflows (degenerate recording) becomes None below, not a warning
            with np.errstate(all="ignore"):
                found, why = _scores(position, values, scale, recording.fs)
            for key, value in found.items():
                scores[f"{prefix}{key}{suffix}"] = value
            notes.update({f"{prefix}{key}{suffix}": note for key, note in why.items()})
    scores["sensor_loop_area"] = _loop_area_or_none(position, recording.sensor)
    flags = use_flags(compensator, recording, estimate)
    scores["extrapolated_fraction"] = compensator.extrapolated_fraction(recording)
    # what the verdict judges: samples beyond the training ranges by FAR_MARGIN of their width
    flags["sensor_far_outside"] = compensator.sensor_outside(recording, margin=FAR_MARGIN)
    flags["estimate_far_outside"] = compensator.estimate_outside(estimate, margin=FAR_MARGIN)
    for name, mask in flags.items():
        scores[f"n_{name}"] = None if mask is None else int(np.sum(mask))
    scores["sensor_margin"], scores["position_margin"] = SENSOR_MARGIN, POSITION_MARGIN
    scores["far_margin"] = FAR_MARGIN
    scores.update(_band_scores(compensator, recording, estimate, level))
    scores["notes"] = notes
    return {key: _finite_or_none(value) for key, value in scores.items()}


def _band_scores(comp: Compensator, recording: Recording, estimate: np.ndarray,
                 level: float | None) -> dict:
    """Coverage, widths and interval score of the compensator's band (None without one)."""
    if comp.band is None:
        return dict.fromkeys(BAND_SCORE_KEYS)
    level = comp.band.level if level is None else level
    lower, upper = interval(comp, recording, estimate, level)
    return interval_scores(recording.position, lower, upper, level)


def _finite_or_none(value: object) -> object:
    """A score that overflowed (a degenerate recording, a huge line) is undefined: None, which
    JSON can hold, instead of inf/NaN, which it cannot."""
    if isinstance(value, float | np.floating):
        return float(value) if np.isfinite(value) else None
    return value


def _r2_or_none(position: np.ndarray, guess: np.ndarray) -> float | None:
    """R² is undefined (None) against a position that never moves."""
    return None if np.ptp(position) == 0 else r2(position, guess)


def _loop_area_or_none(x: np.ndarray, y: np.ndarray) -> float | None:
    """eq. 5.15 normalises by the ranges of x and y: undefined (None) if either is constant."""
    return None if np.ptp(y) == 0 or np.ptp(x) == 0 else loop_area(x, y)


def _sinad_or_none(x: np.ndarray, fs: float) -> tuple[float | None, str | None]:
    """SINAD and None, or None and why: it needs a periodogram long enough to separate the
    tone from DC (:func:`~hystkit.metrics.sinad_db` says how long), and JSON has no inf."""
    try:
        value = sinad_db(x, fs)
    except ValueError as exc:
        return None, f"SINAD n/a: {exc}"
    if not np.isfinite(value):
        return None, "SINAD n/a: nothing is left besides DC and the fundamental (infinite)"
    return value, None
