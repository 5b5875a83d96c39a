"""``hystkit select``: family x size x mode x centring, validated the way it will be used.

Every candidate is fitted and scored on the folds of :mod:`hystkit.compensation._folds` (left-out recording,
or interleaved cycles of one recording), from the training recordings only. The score is the
held-out deployable R² (mean over the folds); the straight line beside it is fitted on the same
training samples. A candidate wins only if it beats its straight line and explains the
position (the shared verdict, :func:`hystkit.compensation.verdict`), and only if its refit on
all the data passes the fit's guards.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from matplotlib.figure import Figure

from .._blas import one_blas_thread
from ..compensation import (
    DEFAULT_CENTER,
    EXTRAPOLATION_NOTE,
    ONE_RUN_CAVEAT,
    Candidate,
    Fold,
    admissible_size,
    check_fitting_data,
    fit_compensator,
    fit_fold,
    fits_in,
    fold_scores,
    folds,
    protocol,
    verdict,
    with_band,
)
from ..io import Recording
from ..models import FAMILIES, get_family
from ..parallel import Executor, SerialExecutor, fit_cost
from ._compare import DISQUALIFYING, FAMILY_FAILURES

__all__ = ["Candidate", "candidates", "plot_selection", "select_model"]

MAX_REFITS = 5


def candidates(models: Sequence[str] | None = None, centers: Sequence[str] = (DEFAULT_CENTER,),
               extra_sizes: dict[str, Sequence[int]] | None = None, *,
               fit_samples: int | None = None, dt: float | None = None) -> list[Candidate]:
    """Every family at its default size (and ``extra_sizes``), direct and, where one exists,
    inverse mode, for each centring.

    Parameters
    ----------
    models : sequence of str, optional
        Family names; None: every registered family, sorted.
    centers : sequence of str, default ("fit",)
        Centrings to try (as :class:`Candidate`).
    extra_sizes : dict of str to sequence of int, optional
        Sizes to try beside the default, per family name; None: ``{"mpl": (1, 3)}``.
    fit_samples : int, optional
        Samples the smallest fold fit sees: sizes needing more are dropped, and a family none
        of whose sizes fits is tried at its largest admissible size (:func:`admissible_size`)
        instead of vanishing. None: no limit.
    dt : float, optional
        Sample time [s], needed with `fit_samples`.

    Returns
    -------
    list of Candidate
        By family, then centring, size and mode.

    Raises
    ------
    InputError
        If a name in ``models`` is not a registered family.
    """
    extra = {"mpl": (1, 3)} if extra_sizes is None else extra_sizes
    out = []
    for name in sorted(FAMILIES) if models is None else models:
        family = get_family(name)
        sizes = sorted({family.default_size, *extra.get(name, ())})
        if fit_samples is not None:
            sizes = [size for size in sizes if fits_in(name, size, dt, fit_samples)] or [
                size for size in [admissible_size(name, dt, fit_samples)] if size is not None]
        modes = ("direct", "inverse") if family.invert is not None else ("direct",)
        out += [Candidate(name, size, mode, center) for center in centers for size in sizes
                for mode in modes]
    return out


def _score_fold(piece: tuple[Candidate, int, dict], *, fold_list: Sequence[Fold]) -> dict:
    """One candidate fitted on one fold's training part and scored on its held-out part."""
    cand, k, options = piece
    fold = fold_list[k]
    try:
        comp = fit_fold(cand, fold, options)
        scores = fold_scores(comp, fold)
        if not np.isfinite(scores["r2"]):
            raise ValueError(f"{fold.label}: held-out R² undefined for this fit")
    except FAMILY_FAILURES as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}
    return {**scores, "status": comp.fit_info["status"], "n_params": comp.fit_info["n_params"]}


def _mean(values: Sequence[float | None]) -> float | None:
    return None if any(v is None for v in values) else float(np.mean(values))


def _candidate_row(cand: Candidate, fold_rows: Sequence[dict], where: str) -> dict:
    """A candidate's validation row from its folds (in fold order): the first failing fold's
    error, or the means over the folds and the shared verdict on them."""
    failed = next((f for f in fold_rows if "error" in f), None)
    if failed is not None:
        return {**_describe(cand), "error": failed["error"]}
    scores = [f["r2"] for f in fold_rows]
    statuses = [f["status"] for f in fold_rows]
    # One bad fold (e.g. a piece that is all rest) does not condemn a family; most folds do.
    failing = [st for st in statuses if st in DISQUALIFYING]
    bad = sorted(set(failing)) if 2 * len(failing) > len(statuses) else []
    cv_r2, cv_line = float(np.mean(scores)), float(np.mean([f["linear_r2"] for f in fold_rows]))
    status, message = verdict(cv_r2, cv_line, where)
    return {**_describe(cand), "cv_r2": cv_r2, "cv_r2_min": float(min(scores)),
            "cv_r2_oracle": _mean([f["r2_oracle"] for f in fold_rows]), "cv_linear_r2": cv_line,
            "n_params": fold_rows[-1]["n_params"],
            "aic": float(np.mean([f["aic"] for f in fold_rows])),
            "bic": float(np.mean([f["bic"] for f in fold_rows])),
            "fold_status": statuses, "guard_failed": ", ".join(bad) or None,
            "verdict": status, "verdict_message": message}


def _describe(cand: Candidate) -> dict:
    return {"candidate": cand.label, "model": cand.model, "size": cand.size, "mode": cand.mode,
            "center": cand.center}


def _rank_key(row: dict) -> tuple:
    if "error" in row:
        return (3, 0.0)
    if row["guard_failed"]:
        return (2, -row["cv_r2"])
    return (0 if row["verdict"] == "ok" else 1, -row["cv_r2"])


def select_model(recordings: Sequence[Recording], cands: Sequence[Candidate], *,
                 executor: Executor | None = None,
                 progress: Callable[[str], None] = lambda _: None, **options) -> dict:
    """Rank candidates by validated deployable R²; refit the best usable one on all recordings.

    Every candidate x fold is one piece of work for `executor` (default: serial); the ranking
    is the same whichever executor ran them. The refit runs here.

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings; the folds are made from them (:func:`folds`).
    cands : sequence of Candidate
        The candidates (:func:`candidates`).
    executor : Executor, optional
        Runs the pieces of work; None: serially, here.
    progress : callable, optional
        Called with one line of text at the start and as each candidate is validated
        (default: nothing).
    **options
        Passed to :func:`hystkit.compensation.fit_compensator` for every fit (e.g.
        ``tare_seconds``, ``slope_cap``).

    Returns
    -------
    dict
        ``protocol`` (its name, ``PROTOCOLS``), ``caveats`` (what this validation cannot
        see), ``ranking`` (rows of candidate, cv_r2, cv_r2_min, cv_r2_oracle, cv_linear_r2,
        n_params, aic, bic, fold_status, guard_failed, verdict, verdict_message; or error),
        ``folds`` (descriptions), ``winner`` (its row) and ``compensator`` (fitted on all
        recordings, with its prediction band calibrated on the same folds), or ``winner`` None with ``refusal`` (one line) when no candidate is
        usable: none beats its straight line and a constant on the held-out data, or none's
        refit passes the fit's guards.

    Raises
    ------
    InputError
        Training data no candidate can be fitted to (too short, constant, a spike); checked
        once before the folds. A candidate that fails in a fold is that candidate's error.
    """
    check_fitting_data(recordings)
    fold_list = folds(recordings)
    name = protocol(recordings)
    executor = executor or SerialExecutor()
    progress(f"  {len(cands)} candidates x {len(fold_list)} folds ({name}) on "
             f"{executor.describe()} ...")
    pieces = [(c, k, options) for c in cands for k in range(len(fold_list))]
    folds_left = [len(fold_list)] * len(cands)

    def fold_done(i: int, _: dict) -> None:
        j = i // len(fold_list)
        folds_left[j] -= 1
        if not folds_left[j]:
            progress(f"  {cands[j].label}: validated ({folds_left.count(0)}/{len(cands)})")

    fold_rows = executor.map(_score_fold, pieces, shared={"fold_list": fold_list},
                             on_done=fold_done, cost=lambda piece: fit_cost(
                                 piece[0].model, piece[0].size, fold_list[piece[1]].n_train))
    rows = [_candidate_row(c, fold_rows[j * len(fold_list):(j + 1) * len(fold_list)],
                           f"held-out ({name})") for j, c in enumerate(cands)]
    rows.sort(key=_rank_key)
    caveats = [] if len(recordings) > 1 else [ONE_RUN_CAVEAT]
    worst = max((f.extrapolated() for f in fold_list), default=0.0)
    if worst > EXTRAPOLATION_NOTE:
        caveats.append(f"the folds cannot cover the range: up to {worst:.0%} of a fold's "
                       f"held-out positions lie outside its training positions, so the scores "
                       f"partly measure extrapolation")
    out = {"protocol": name, "caveats": caveats,
           "folds": [{"train": [r.source for r in f.train], "test": f.label,
                      "extrapolated": f.extrapolated()} for f in fold_list],
           "ranking": rows, "winner": None, "compensator": None, "refusal": None}
    usable = [r for r in rows if "error" not in r and not r["guard_failed"]
              and r["verdict"] == "ok"]
    if not usable:
        out["refusal"] = _refusal(rows, name)
        return out
    for row in usable[:MAX_REFITS]:
        try:
            # BLAS on one thread, as in every fold fit (on a worker or `SerialExecutor`): the
            # refit's standard errors take QR factors of chunks of (~1000 x n_params) rows,
            # too small for threads, and idle OpenBLAS threads spin (measured: the Preisach
            # refit 0.4 s with one thread, 0.8-3.4 s with two on a busy 2-core machine).
            with one_blas_thread():
                comp = fit_compensator(list(recordings), row["size"], model=row["model"],
                                       mode=row["mode"], center=row["center"], **options)
        except FAMILY_FAILURES as exc:
            row["error_final"] = str(exc)
            continue
        row["final_status"] = comp.fit_info["status"]
        if comp.fit_info["status"] != "ok":
            row["error_final"] = (f"its fit on all the data: {comp.fit_info['status']}: "
                                  f"{comp.fit_info['status_message']}")
            continue
        # the winner's band, from the same folds it was validated on
        with one_blas_thread():
            comp = with_band(comp, list(recordings), row["size"], options)
        out["winner"], out["compensator"] = row, comp
        return out
    out["refusal"] = (f"the best {min(len(usable), MAX_REFITS)} candidate(s) beat their "
                      f"straight line held out, but none's fit on all the data passed its "
                      f"guards (see error_final)")
    return out


def _refusal(rows: Sequence[dict], name: str) -> str:
    """Why no candidate can win, in one line."""
    scored = [r for r in rows if "error" not in r]
    if not scored:
        return "every candidate failed in its folds (reasons in the table)"
    best = max(scored, key=lambda r: r["cv_r2"])
    if all(r["verdict"] == "no_signal" for r in scored):
        return (f"no candidate explains the position on held-out data ({name}): the best, "
                f"{best['candidate']}, has R² {best['cv_r2']:.4f}; check that the sensor "
                f"column carries the measurand")
    return (f"no candidate beats its straight line and a constant on held-out data ({name}): "
            f"the best, {best['candidate']}, has R² {best['cv_r2']:.4f} against its line's "
            f"{best['cv_linear_r2']:.4f}")


def plot_selection(ranking: Sequence[dict]) -> Figure:
    """Held-out R² of every candidate as 1 - R² on a log scale (the deployable score, the
    straight line and, where it means something, the oracle), so that close candidates are
    told apart.

    Parameters
    ----------
    ranking : sequence of dict
        The ``ranking`` rows of :func:`select_model`; rows with an error are left out.

    Returns
    -------
    matplotlib.figure.Figure
        One row per candidate, best at the top, its R² written beside each marker.
    """
    # with matplotlib (~0.3 s), which select without --report never needs
    from ._report_folders import plot_unexplained

    rows = [r for r in ranking if "error" not in r]
    return plot_unexplained(
        [(r["candidate"] + ("" if r["verdict"] == "ok" and not r["guard_failed"] else " ✗"),
          {"deployable (mean over folds)": r["cv_r2"], "straight line": r["cv_linear_r2"],
           "oracle": r["cv_r2_oracle"]}) for r in rows],
        "held-out 1 − R² (log scale, left is better; dashed: R² = 0; ✗: not usable)")
