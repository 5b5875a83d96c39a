"""Calibrating a compensator's prediction band (:mod:`._band`) on held-out runs.

The validation folds of ``select`` (:mod:`._folds`): each refits the same model on its
training part and runs it over its held-out run from the start, as in use; the held-out errors,
normalised by the band's local scale, give the conformal quantiles the model file keeps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ..errors import FitDivergedError, InputError
from ..io import Recording
from ._band import (
    DEFAULT_LEVEL,
    MAX_RATE_SHARE,
    MIN_CALIBRATION,
    MIN_TAU_S,
    QUANTILE_GRID,
    TAU_SAMPLES,
    Band,
    band_features,
    check_level,
    position_width,
    rate_scale,
)
from ._folds import Candidate, fit_fold, folds, protocol

__all__ = ["calibrate_band", "with_band"]


def with_band(comp, recordings: Sequence[Recording], size: int, options: dict | None = None,
              *, level: float = DEFAULT_LEVEL):
    """`comp` with its band calibrated (:func:`calibrate_band`); ``fit_info["band"]`` says
    from which protocol and how many held-out samples, or why there is none.

    Parameters
    ----------
    comp : Compensator
        Fitted on `recordings` by :func:`~hystkit.compensation.fit_compensator`.
    recordings : sequence of Recording
        Its training recordings.
    size : int
        The family's size knob it was fitted with.
    options : dict, optional
        The other options of its fit.
    level : float, default 0.90
        The band's nominal level.

    Returns
    -------
    Compensator
        A copy with ``band`` set (None if it could not be calibrated).
    """
    band, note = calibrate_band(comp, recordings, size, options, level=level)
    return replace(comp, band=band, fit_info=comp.fit_info.with_entries(band=note))


def calibrate_band(comp, recordings: Sequence[Recording], size: int,
                   options: dict | None = None, *,
                   level: float = DEFAULT_LEVEL) -> tuple[Band | None, str]:
    """The band of `comp`, calibrated on the validation folds of its training recordings.

    Each fold refits the same model (family, size, mode, centring, `options`) on the fold's
    training part, runs it on the held-out part from its start and keeps the held-out errors.

    Parameters
    ----------
    comp : Compensator
        The compensator fitted on all of `recordings`.
    recordings : sequence of Recording
        Its training recordings.
    size : int
        The family's size knob it was fitted with.
    options : dict, optional
        The fit's other options (:func:`~hystkit.compensation.fit_compensator`).
    level : float, default 0.90
        The nominal level stored as the band's default.

    Returns
    -------
    band : Band or None
        None when it cannot be calibrated (then `note` says why).
    note : str
        The protocol and number of held-out samples, or why there is no band.
    """
    check_level(level)
    options = dict(options or {})
    if comp.training_range is None or comp.position_range is None:
        return None, "no band: the model does not know its training ranges"
    if options.get("weights") and len(recordings) == 1:
        return None, ("no band: --weights and the held-out pieces of one recording both weight "
                      "the samples; give several recordings (one per run) for a band")
    tau = max(TAU_SAMPLES * comp.structure.dt, MIN_TAU_S)
    train_rate = np.concatenate([
        band_features(comp.normalised_sensor(r.sensor), comp.structure.dt, tau,
                      comp.training_range)[0] for r in recordings])
    rate_reference = float(np.mean(train_rate))
    if not rate_reference > 0:
        return None, "no band: the training sensor does not move"
    rate_high = max(float(np.quantile(train_rate, 0.99)), rate_reference)
    errors, rates, excess = [], [], []
    failed = []
    for fold in folds(recordings):
        try:
            fold_comp = fit_fold(Candidate(comp.model, size, comp.mode, comp.center), fold, options)
            estimate = fold_comp.estimate(fold.scored, rest_position=_rest(fold_comp, fold))
        except (FitDivergedError, InputError, ValueError, np.linalg.LinAlgError) as exc:
            failed.append(f"{fold.label}: {exc}")
            continue
        held = slice(None) if fold.held is None else fold.held
        s = fold_comp.normalised_sensor(fold.scored.sensor)
        rate, outside, _ = band_features(s, comp.structure.dt, tau, fold_comp.training_range)
        errors.append(np.abs(fold.scored.position - estimate)[held])
        rates.append(rate[held])
        excess.append((position_width(fold_comp) * outside)[held])
    if not errors:
        return None, (f"no band: every fold's fit failed ({failed[0]})" if failed else
                      "no band: no fold's held-out position moves (nothing to score)")
    error, rate, extra = (np.concatenate(v) for v in (errors, rates, excess))
    if error.size < MIN_CALIBRATION:
        return None, (f"no band: {error.size} held-out samples, fewer than "
                      f"{MIN_CALIBRATION}")
    beyond = np.maximum(error - extra, 0.0)
    share = _rate_share(beyond, rate / rate_reference)
    scores = beyond / rate_scale(rate, share, rate_reference, rate_high)
    band = Band(level, tuple(np.quantile(scores, QUANTILE_GRID)), error.size, tau,
                rate_reference, rate_high, share, protocol(recordings))
    note = f"band: {band.protocol}, {error.size} held-out samples"
    if len(recordings) == 1:
        note += ("; one recording: it holds for runs like this one, not for an offset, gain or "
                 "excitation that changes between runs (give several recordings)")
    if failed:
        note += f" ({len(failed)} fold(s) failed and are left out: {failed[0]})"
    return band, note


def _rate_share(error: np.ndarray, rate: np.ndarray) -> float:
    """How much of the held-out error grows with the rate: ``c1 / (c0 + c1)`` of the
    non-negative least-squares fit ``|e| ~ c0 + c1 rate``, at most ``MAX_RATE_SHARE``.

    Two coefficients: the unconstrained line if both are >= 0, else the better of the two
    one-coefficient fits (the Karush-Kuhn-Tucker cases of NNLS, without scipy.optimize).
    """
    candidates = [(float(np.mean(error)), 0.0)]
    rr = float(rate @ rate)
    if rr > 0:
        candidates.append((0.0, float(rate @ error) / rr))
    if np.ptp(rate) > 0:
        c1, c0 = np.polyfit(rate, error, 1)
        candidates.append((float(c0), float(c1)))
    feasible = [(c0, c1) for c0, c1 in candidates if c0 >= 0 and c1 >= 0]
    c0, c1 = min(feasible, key=lambda c: float(np.sum((error - c[0] - c[1] * rate) ** 2)))
    total = c0 + c1
    return 0.0 if total <= 0 else float(min(c1 / total, MAX_RATE_SHARE))


def _rest(comp, fold) -> float | None:
    """A left-out recording's rest position for ``tare`` (the user tares there)."""
    if comp.center != "tare" or fold.held is not None:
        return None
    n_tare = max(1, round(comp.tare_seconds / fold.scored.dt))
    return float(np.mean(fold.scored.position[:n_tare]))
