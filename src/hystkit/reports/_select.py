"""``hystkit select``: family x size x mode (x centring) by cross-validation on training data.

Only the training recordings are used: leave-one-recording-out when there are several, blocked
time folds otherwise (each fold trains on the other blocks as separate recordings, so no state
crosses a gap). The score is the *deployable* held-out R²; AIC / BIC of the fold fits are shown
beside it, and a candidate whose fit fails its guards in any fold (collapsed, worse than the
line) in most folds is ranked after every candidate that passes.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure
from threadpoolctl import threadpool_limits

from ..compensation import DEFAULT_CENTER, check_fitting_data, evaluate, fit_compensator
from ..errors import FitDivergedError
from ..io import Recording
from ..models import FAMILIES, get_family
from ..parallel import Executor, SerialExecutor, fit_cost
from ._compare import DISQUALIFYING, FAMILY_FAILURES

__all__ = ["Candidate", "candidates", "folds", "plot_selection", "select_model"]

N_TIME_FOLDS = 3


@dataclass(frozen=True)
class Candidate:
    """One model configuration that :func:`select_model` cross-validates.

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


def candidates(models: Sequence[str] | None = None, centers: Sequence[str] = (DEFAULT_CENTER,),
               extra_sizes: dict[str, Sequence[int]] | None = None) -> list[Candidate]:
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
        modes = ("direct", "inverse") if family.invert is not None else ("direct",)
        out += [Candidate(name, size, mode, center) for center in centers for size in sizes
                for mode in modes]
    return out


def folds(recordings: Sequence[Recording]) -> list[tuple[list[Recording], Recording]]:
    """(training recordings, held-out recording) pairs; see the module docstring.

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings (at least one).

    Returns
    -------
    list of (list of Recording, Recording)
        Leave-one-recording-out pairs for several recordings; for one, three blocked time
        folds (a block without motion only trains, it is never held out).
    """
    if len(recordings) > 1:
        return [([r for j, r in enumerate(recordings) if j != i], held)
                for i, held in enumerate(recordings)]
    rec = recordings[0]
    edges = np.linspace(0, rec.n_samples, N_TIME_FOLDS + 1).astype(int)
    blocks = [_block(rec, a, b, k) for k, (a, b) in enumerate(itertools.pairwise(edges))]
    # A block without motion (a rest period) cannot be scored by R²; it still trains.
    return [([b for j, b in enumerate(blocks) if j != i], held) for i, held in enumerate(blocks)
            if np.ptp(held.position) > 0]


def _block(rec: Recording, start: int, stop: int, k: int) -> Recording:
    return Recording(time=rec.time[start:stop] - rec.time[start], sensor=rec.sensor[start:stop],
                     position=rec.position[start:stop], source=f"{rec.source}[block {k + 1}]")


def _score_fold(piece: tuple[Candidate, int, dict], *, pairs: Sequence) -> dict:
    """One candidate fitted on one fold's training part and scored on its held-out part."""
    cand, k, options = piece
    train, held = pairs[k]
    try:
        comp = fit_compensator(train, cand.size, model=cand.model, mode=cand.mode,
                               center=cand.center, diagnose=False, **options)
        s = evaluate(comp, held)
        if s["r2"] is None:  # evaluate gives None where R² is undefined or overflowed
            raise FitDivergedError(f"{held.source}: held-out R² undefined for this fit")
    except FAMILY_FAILURES as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}
    info = comp.fit_info
    return {"r2": s["r2"], "r2_oracle": s["r2_oracle"], "linear_r2": s["linear_r2"],
            "aic": info["aic"], "bic": info["bic"], "status": info["status"],
            "n_params": info["n_params"]}


def _candidate_row(cand: Candidate, fold_rows: Sequence[dict]) -> dict:
    """A candidate's cross-validation row from its folds (in fold order): the first failing
    fold's error, or the means over the folds."""
    failed = next((f for f in fold_rows if "error" in f), None)
    if failed is not None:
        return {**_describe(cand), "error": failed["error"]}
    scores = [f["r2"] for f in fold_rows]
    statuses = [f["status"] for f in fold_rows]
    # One bad fold (e.g. a block that is all rest) does not condemn a family; most folds do.
    failing = [st for st in statuses if st in DISQUALIFYING]
    bad = sorted(set(failing)) if 2 * len(failing) > len(statuses) else []
    mean = lambda key: float(np.mean([f[key] for f in fold_rows]))
    return {**_describe(cand), "cv_r2": float(np.mean(scores)), "cv_r2_min": float(min(scores)),
            "cv_r2_oracle": mean("r2_oracle"), "cv_linear_r2": mean("linear_r2"),
            "n_params": fold_rows[-1]["n_params"], "aic": mean("aic"), "bic": mean("bic"),
            "fold_status": statuses, "guard_failed": ", ".join(bad) or None}


def _describe(cand: Candidate) -> dict:
    return {"candidate": cand.label, "model": cand.model, "size": cand.size, "mode": cand.mode,
            "center": cand.center}


def _rank_key(row: dict) -> tuple:
    if "error" in row:
        return (2, 0.0)
    return (1 if row["guard_failed"] else 0, -row["cv_r2"])


def select_model(recordings: Sequence[Recording], cands: Sequence[Candidate], *,
                 executor: Executor | None = None,
                 progress: Callable[[str], None] = lambda _: None, **options) -> dict:
    """Rank candidates by cross-validated deployable R²; refit the winner on all recordings.

    Every candidate x fold is one piece of work for `executor` (default: serial); the ranking
    is the same whichever executor ran them. The winner's refit runs here.

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings; the folds are made from them (:func:`folds`).
    cands : sequence of Candidate
        The candidates (:func:`candidates`).
    executor : Executor, optional
        Runs the pieces of work; None: serially, here.
    progress : callable, optional
        Called with one line of text at the start and as each candidate is cross-validated
        (default: nothing).
    **options
        Passed to :func:`hystkit.compensation.fit_compensator` for every fit (e.g.
        ``tare_seconds``, ``slope_cap``).

    Returns
    -------
    dict
        ``ranking`` (rows of candidate, cv_r2, cv_r2_min, cv_r2_oracle, cv_linear_r2, n_params,
        aic, bic, fold_status, guard_failed, or error), ``folds`` (descriptions), ``winner``
        (its row) and ``compensator`` (fitted on all recordings), or ``winner`` None when
        every candidate failed.

    Raises
    ------
    InputError
        Training data no candidate can be fitted to (too short, constant, a spike); checked
        once before the folds. A candidate that fails in a fold is that candidate's error.
    """
    check_fitting_data(recordings)
    pairs = folds(recordings)
    executor = executor or SerialExecutor()
    progress(f"  {len(cands)} candidates x {len(pairs)} folds on {executor.describe()} ...")
    pieces = [(c, k, options) for c in cands for k in range(len(pairs))]
    folds_left = [len(pairs)] * len(cands)

    def fold_done(i: int, _: dict) -> None:
        j = i // len(pairs)
        folds_left[j] -= 1
        if not folds_left[j]:
            progress(f"  {cands[j].label}: cross-validated "
                     f"({folds_left.count(0)}/{len(cands)})")

    fold_rows = executor.map(_score_fold, pieces, shared={"pairs": pairs}, on_done=fold_done,
                             cost=lambda piece: fit_cost(piece[0].model, piece[0].size, sum(
                                 rec.sensor.size for rec in pairs[piece[1]][0])))
    rows = [_candidate_row(c, fold_rows[j * len(pairs):(j + 1) * len(pairs)])
            for j, c in enumerate(cands)]
    rows.sort(key=_rank_key)
    out = {"folds": [{"train": [r.source for r in train], "test": held.source}
                     for train, held in pairs], "ranking": rows, "winner": None,
           "compensator": None}
    for row in rows:
        if "error" in row or row["guard_failed"]:
            continue
        try:
            # BLAS on one thread, as in every fold fit (on a worker or `SerialExecutor`): the
            # refit's standard errors take QR factors of chunks of (~1000 x n_params) rows,
            # too small for threads, and idle OpenBLAS threads spin (measured: the Preisach
            # refit 0.4 s with one thread, 0.8-3.4 s with two on a busy 2-core machine).
            with threadpool_limits(limits=1, user_api="blas"):
                out["compensator"] = fit_compensator(list(recordings), row["size"],
                                                     model=row["model"], mode=row["mode"],
                                                     center=row["center"], **options)
        except FAMILY_FAILURES as exc:
            row["error_final"] = str(exc)
            continue
        out["winner"] = row
        break
    return out


def plot_selection(ranking: Sequence[dict]) -> Figure:
    """Held-out deployable R² per candidate (oracle and straight line as markers).

    Parameters
    ----------
    ranking : sequence of dict
        The ``ranking`` rows of :func:`select_model`; rows with an error are left out.

    Returns
    -------
    matplotlib.figure.Figure
        One bar per candidate, grey where its fit failed its guards; R² below -0.5 is drawn
        at -0.5.
    """
    rows = [r for r in ranking if "error" not in r]
    fig = Figure(figsize=(7, 0.3 * len(rows) + 1.5), layout="constrained")
    ax = fig.subplots()
    y = np.arange(len(rows))[::-1]
    clip = lambda v: max(v, -0.5)
    ax.barh(y, [clip(r["cv_r2"]) for r in rows],
            color=["tab:gray" if r["guard_failed"] else "tab:blue" for r in rows],
            label="deployable R² (mean over folds)")
    ax.plot([clip(r["cv_r2_oracle"]) for r in rows], y, "k|", ms=10, label="oracle R²")
    ax.plot([clip(r["cv_linear_r2"]) for r in rows], y, "rx", label="straight line")
    ax.set(yticks=y, yticklabels=[r["candidate"] for r in rows], xlabel="held-out R²",
           xlim=(min(0.0, *(clip(r["cv_r2"]) for r in rows)) if rows else 0.0, 1.0))
    ax.legend(loc="lower left", fontsize="small")
    return fig
