"""How a model is validated the way it will be used: the folds of ``select``.

- Several recordings (one per run): **left-out recording**. Each is held out in turn; a
  candidate is fitted on the others and run on it, from its start.
- One recording: **interleaved cycles of the training recording**. It is cut into
  ``N_SEGMENTS`` pieces and fold k holds out every ``N_FOLDS``-th piece from the k-th, so that
  every fold is fitted on the input range it is scored on. The fit gives the held-out pieces
  zero weight; the compensator runs over the whole recording from its start and is scored on
  the held-out samples only.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..io import Recording
from ..metrics import r2
from ..models import get_family
from ._fitting import fit_compensator
from ._training_checks import MIN_SAMPLES_PER_PARAM, count_fitted

__all__ = [
    "EXTRAPOLATION_NOTE",
    "N_FOLDS",
    "ONE_RUN_CAVEAT",
    "PROTOCOLS",
    "Candidate",
    "Fold",
    "admissible_size",
    "fit_fold",
    "fits_in",
    "fold_scores",
    "folds",
    "protocol",
]

N_FOLDS = 3
# Pieces of one recording: N_FOLDS interleaved sets of N_SEGMENTS / N_FOLDS each.
N_SEGMENTS = 12
# Shortest piece worth holding out (fewer samples: fewer pieces).
MIN_SEGMENT = 20
PROTOCOLS = {"recordings": "left-out recording",
             "cycles": "interleaved cycles of the training recording"}
ONE_RUN_CAVEAT = ("one recording: an offset that changes between runs is invisible to this "
                  "validation; give several recordings (one per run) to see it")
# A fold whose held-out positions lie this much outside its training range measures
# extrapolation, not use; the output says so.
EXTRAPOLATION_NOTE = 0.05
# Refits tried, best first, before select gives up on the candidates whose refit fails.
_WEIGHTS = "select: training samples of the fold"


@dataclass(frozen=True)
class Fold:
    """One validation fold: fit on ``train``, run on ``scored``, score ``held`` samples.

    Parameters
    ----------
    train : list of Recording
        The recordings the fold's fits see.
    scored : Recording
        The recording the fitted compensator is run on, from its start.
    held : numpy.ndarray of bool or None
        The samples of `scored` that are scored and that the fit does not see (weight zero);
        None: all of `scored`, a recording the fit never saw.
    label : str
        What is held out, for the outputs.
    """

    train: list[Recording]
    scored: Recording
    held: np.ndarray | None
    label: str

    @property
    def n_train(self) -> int:
        """Samples the fold's fit is fitted on."""
        if self.held is not None:
            return int(np.count_nonzero(~self.held))
        return sum(r.n_samples for r in self.train)

    def extrapolated(self) -> float:
        """Share of the held-out positions outside the range of the fold's training positions
        (the measurand's range: a sensor's offset may differ between runs, its range not)."""
        if self.held is None:
            lo = min(float(r.position.min()) for r in self.train)
            hi = max(float(r.position.max()) for r in self.train)
            p = self.scored.position
        else:
            lo, hi = (float(f(self.scored.position[~self.held])) for f in (np.min, np.max))
            p = self.scored.position[self.held]
        return float(np.mean((p < lo) | (p > hi)))


@dataclass(frozen=True)
class Candidate:
    """One model configuration: what ``select`` validates and a fold refits.

    Parameters
    ----------
    model : str
        Registered family name.
    size : int
        The family's size (mPL: cells N).
    mode : {"direct", "inverse"}
        Compensator mode.
    center : {"fit", "tare", "track", "recording", "none"}
        Centring (:func:`hystkit.compensation.fit_compensator`).
    """

    model: str
    size: int
    mode: str
    center: str

    @property
    def label(self) -> str:
        return f"{self.model}:{self.size}:{self.mode}:{self.center}"


def protocol(recordings: Sequence[Recording]) -> str:
    """The validation protocol's name for these training recordings (:data:`PROTOCOLS`).

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings.

    Returns
    -------
    str
    """
    return PROTOCOLS["recordings" if len(recordings) > 1 else "cycles"]


def folds(recordings: Sequence[Recording]) -> list[Fold]:
    """The validation folds of the training recordings; see the module docstring.

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings (at least one).

    Returns
    -------
    list of Fold
        One per recording for several (leave-one-recording-out); for one, ``N_FOLDS``
        interleaved sets of pieces. A fold whose held-out position does not move (a rest
        period) cannot be scored by R² and is left out; its samples still train.
    """
    if len(recordings) > 1:
        return [Fold([r for j, r in enumerate(recordings) if j != i], held, None,
                     f"recording {held.source}")
                for i, held in enumerate(recordings)]
    rec = recordings[0]
    n_pieces = max(N_FOLDS, min(N_SEGMENTS, rec.n_samples // MIN_SEGMENT))
    piece = np.minimum(np.arange(rec.n_samples) * n_pieces // rec.n_samples, n_pieces - 1)
    out = []
    for k in range(N_FOLDS):
        held = piece % N_FOLDS == k
        if np.ptp(rec.position[held]) > 0:
            pieces = ", ".join(str(i + 1) for i in range(k, n_pieces, N_FOLDS))
            out.append(Fold([rec], rec, held, f"pieces {pieces} of {n_pieces} of {rec.source}"))
    return out


def fits_in(model: str, size: int, dt: float, n_samples: int) -> bool:
    """Whether `n_samples` can fit the family at `size` (``MIN_SAMPLES_PER_PARAM`` samples per
    fitted number; a size the family refuses cannot).

    Parameters
    ----------
    model : str
        A registered family name.
    size : int
        The family's size knob.
    dt : float
        Sample time [s] of the data.
    n_samples : int
        Samples the fit sees.

    Returns
    -------
    bool
    """
    family = get_family(model)
    try:
        n_params = count_fitted(family, family.make_structure(dt, size))
    except (ValueError, TypeError):
        return False
    return n_params is None or MIN_SAMPLES_PER_PARAM * n_params <= n_samples


def admissible_size(model: str, dt: float, n_samples: int) -> int | None:
    """Largest size up to the family's default that `n_samples` can fit (:func:`fits_in`),
    or None if not even size 1 can.

    Parameters
    ----------
    model : str
        A registered family name.
    dt : float
        Sample time [s] of the data.
    n_samples : int
        Samples the smallest fit will see.

    Returns
    -------
    int or None
    """
    return next((size for size in range(get_family(model).default_size, 0, -1)
                 if fits_in(model, size, dt, n_samples)), None)


def fit_fold(cand: Candidate, fold: Fold, options: dict):
    """A model configuration fitted on a fold's training part (no standard errors).

    Parameters
    ----------
    cand : Candidate
        The configuration (select's candidates, the band's refits).
    fold : Fold
        The fold; its held-out samples get weight zero (one recording) or are another
        recording.
    options : dict
        Further options of :func:`~hystkit.compensation.fit_compensator`.

    Returns
    -------
    Compensator
        Fitted on the fold's training part.
    """
    if fold.held is None:
        return fit_compensator(fold.train, cand.size, model=cand.model, mode=cand.mode,
                               center=cand.center, diagnose=False, **options)
    return fit_compensator(fold.train, cand.size, model=cand.model, mode=cand.mode,
                           center=cand.center, diagnose=False, weights=_WEIGHTS,
                           other_columns=[{_WEIGHTS: (~fold.held).astype(float)}], **options)


def fold_scores(comp, fold: Fold) -> dict:
    """The fold's held-out scores of a compensator fitted on its training part.

    Parameters
    ----------
    comp : Compensator
        Fitted on ``fold.train`` (with zero weight on ``fold.held``).
    fold : Fold
        The fold.

    Returns
    -------
    dict
        ``r2`` (deployable), ``linear_r2`` (the straight line fitted on the fold's training
        samples, same centring), ``r2_oracle`` (the paper's protocol; None unless the
        centring is ``fit``: for ``tare`` / ``track`` the oracle replaces the very offset
        being judged), ``aic`` / ``bic`` of the fit on its training samples.
    """
    rec = fold.scored
    rest = None
    if comp.center == "tare" and fold.held is None:
        n_tare = max(1, round(comp.tare_seconds / rec.dt))
        rest = float(np.mean(rec.position[:n_tare]))
    guess = comp.estimate(rec, rest_position=rest)
    if fold.held is None:
        scored, line = slice(None), comp.estimate_linear(rec, rest_position=rest)
    else:
        scored = fold.held
        s = comp.normalised_sensor(rec.sensor)
        slope, intercept = np.polyfit(s[~scored], rec.position[~scored], 1)
        line = slope * s + intercept
    p = rec.position[scored]
    out = {"r2": r2(p, guess[scored]), "linear_r2": r2(p, line[scored]), "r2_oracle": None}
    if comp.center == "fit":
        oracle = comp.oracle().estimate(rec, float(np.mean(rec.position)))
        out["r2_oracle"] = r2(p, oracle[scored])
    info = comp.fit_info
    if fold.held is None:
        out["aic"], out["bic"] = info["aic"], info["bic"]
    else:
        fit_part = ~fold.held
        resid = (guess[fit_part] - rec.position[fit_part]) / comp.scaling.position_scale
        n, k = resid.size, info["n_params"]
        log_term = n * np.log(max(float(resid @ resid), 1e-300) / n)
        out["aic"], out["bic"] = float(log_term + 2 * k), float(log_term + k * np.log(n))
    return out
