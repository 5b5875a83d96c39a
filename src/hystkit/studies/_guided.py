"""The guided first fit's selection (``hystkit fit --model auto``, issue 27.5).

A short, fixed list of small candidates goes through ``select``'s machinery (the same folds,
score, verdict, refit of the winner and band: :func:`select_model`) under a
time budget, and the choice is explained in three lines. The list covers what a cheap
hysteretic sensor usually shows with the cheapest families that show it:

- ``mpl`` 1 cell: the plain default fit (one hysteresis time scale, an odd static curve);
- ``pi`` 10 play operators: rate-independent hysteresis with creep (a drifting piezo);
- ``mpl-poly`` 1 cell: cubic resistors, a curved (e.g. quadratic) static characteristic such as
  a piezoresistive sensor's, which ``mpl`` can only pin on its bounds;
- ``mpl`` 2 and 3 cells: more time scales, for relaxation and drift beside the hysteresis;
- ``pl`` 1 cell: the Power-Law as published, another shape of the static curve.

Measured on 2 cores at load 2-6 (6 candidates x 3 folds, the winner's refit and band, wall
time of the command): 23 s on a simulated piezoresistive sensor of 10,000 samples, 31 s on the
MR damper's 11,274, 18 s on the micromanipulator's 14,154; on the piezo actuator's 50,001, 49 s
with mpl:3 skipped for the budget. Candidates run cheapest first (:func:`hystkit.parallel.fit_cost`);
a piece of work not started within ``VALIDATION_SHARE`` of the budget is skipped (its
candidate said so), which leaves the rest to the winner's refit and band; a candidate whose
a-priori cost alone (a floor: measured on easy data) exceeds that share is not started at all.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from functools import partial

from ..compensation import (
    MIN_EXPLAINED,
    MIN_USABLE,
    Candidate,
    check_fitting_data,
    fits_in,
    folds,
    protocol,
)
from ..models import get_family
from ..parallel import SerialExecutor, fit_cost
from ._select import select_model

__all__ = ["DEFAULT_BUDGET", "SHORT_LIST", "explain_choice", "guided_candidates",
           "guided_select", "selection_status"]

# Seconds for the whole guided fit (issue 27.5: <= 60 s for 10,000 samples on 2 cores)
DEFAULT_BUDGET = 60.0
# (family, size), see the module docstring for why these
SHORT_LIST = (("mpl", 1), ("pi", 10), ("mpl-poly", 1), ("mpl", 2), ("pl", 1), ("mpl", 3))
# Share of the budget in which validation pieces may start; the rest is for the pieces still
# running and the winner's refit and band (measured: 20-35 % of the whole on 10,000 samples)
VALIDATION_SHARE = 0.5
SKIPPED = "not validated: its turn came after the time budget's validation share"


def guided_candidates(recordings: Sequence, mode: str = "direct", center: str = "fit"
                      ) -> list:
    """`SHORT_LIST` as `hystkit.compensation.Candidate`, cheapest first, without those the
    smallest fold cannot fit (too few samples per parameter) or that have no inverse.

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings (their folds decide what fits).
    mode : {"direct", "inverse"}, default "direct"
        The compensator's mode; ``"inverse"`` keeps the families with an inverse.
    center : str, default "fit"
        The centring of every candidate.

    Returns
    -------
    list of Candidate
        The candidates, cheapest fit first.
    """
    n_train = min((f.n_train for f in folds(recordings)), default=0)
    dt = recordings[0].dt
    kept = [Candidate(name, size, mode, center) for name, size in SHORT_LIST
            if fits_in(name, size, dt, n_train)
            and (mode == "direct" or get_family(name).invert is not None)]
    return sorted(kept, key=lambda c: fit_cost(c.model, c.size, n_train))


def _unless_late(func: Callable, deadline: float, item, **shared):
    """One piece of `select_model`'s map, unless the validation's time is up."""
    if time.time() > deadline:  # wall clock: the same in forked workers
        return {"error": SKIPPED}
    return func(item, **shared)


class _Budgeted:
    """An executor that runs the pieces in the order given (cheapest candidates first) and
    starts none after `deadline` (seconds since the epoch); ``late`` collects the labels of
    the candidates (a piece's first element) with a piece skipped."""

    def __init__(self, inner, deadline: float):
        self.inner, self.deadline, self.n_workers = inner, deadline, inner.n_workers
        self.late: set[str] = set()

    def describe(self) -> str:
        return self.inner.describe()

    def map(self, func, items, *, shared=None, on_done=None, cost=None) -> list:
        rank = {id(item): i for i, item in enumerate(items)}

        def done(i: int, result) -> None:
            if isinstance(result, dict) and result.get("error") == SKIPPED:
                self.late.add(items[i][0].label)
            if on_done is not None:
                on_done(i, result)

        return self.inner.map(partial(_unless_late, func, self.deadline), items, shared=shared,
                              on_done=done, cost=lambda item: -rank[id(item)])


def guided_select(recordings: Sequence, *, budget: float = DEFAULT_BUDGET, mode: str = "direct",
                  center: str = "fit", executor=None,
                  progress: Callable[[str], None] = lambda _: None, **options) -> dict:
    """`hystkit.studies.select_model` over `guided_candidates` within `budget` seconds.

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings (one per run: left-out recording; one: interleaved cycles).
    budget : float
        Seconds for the whole (see the module docstring for how it is kept).
    mode, center : str
        Every candidate's mode and centring.
    executor : Executor, optional
        Where the validation runs; None: serially, here.
    progress : callable
        Called with one line as candidates are validated.
    **options
        Passed to every fit (``tare_seconds``, ``track_seconds``).

    Returns
    -------
    dict
        `select_model`'s result (``winner``, ``compensator``, ``ranking``, ``protocol``,
        ``refusal``, ...) without the skipped candidates' rows, plus ``skipped`` (label,
        reason) and ``candidates`` (the labels tried).
    """
    t0 = time.time()
    check_fitting_data(recordings)
    executor = executor or SerialExecutor()
    fold_list = folds(recordings)
    n_train = min((f.n_train for f in fold_list), default=0)
    share = VALIDATION_SHARE * budget
    cands, skipped, planned = [], [], 0.0
    for cand in guided_candidates(recordings, mode, center):
        floor = fit_cost(cand.model, cand.size, n_train) * len(fold_list) / executor.n_workers
        if planned + floor > share:
            why = f"its folds alone would take at least {floor:.0f} s of the {share:.0f} s"
            skipped.append((cand.label, why + " for validation"))
            continue
        planned += floor
        cands.append(cand)
    if not cands:
        return {"winner": None, "compensator": None, "ranking": [], "skipped": skipped,
                "candidates": [], "protocol": protocol(recordings), "caveats": [], "folds": [],
                "refusal": f"no candidate can be validated within the {budget:g} s budget"}
    budgeted = _Budgeted(executor, t0 + share)

    def say(line: str) -> None:  # select_model counts a skipped candidate as validated
        if line.strip().split(": ")[0] in budgeted.late:
            line = line.replace(": validated", ": skipped (time budget)")
        progress(line)

    result = select_model(recordings, cands, executor=budgeted, progress=say, **options)
    late = [r for r in result["ranking"] if r.get("error") == SKIPPED]
    result["ranking"] = [r for r in result["ranking"] if r.get("error") != SKIPPED]
    result["skipped"] = skipped + [(r["candidate"], SKIPPED) for r in late]
    result["candidates"] = [c.label for c in cands]
    if result["winner"] is None and not result["ranking"]:
        result["refusal"] = f"no candidate was validated within the {budget:g} s budget"
    return result


def selection_status(result: dict) -> str:
    """Why a selection has no winner, as a `next_step` status.

    Parameters
    ----------
    result : dict
        What the selection returned (``winner``, ``ranking``, ``skipped``).

    Returns
    -------
    str
        ``no_signal`` (no candidate explains the position), ``poor`` (none, and not the
        straight line either, explains ``MIN_USABLE`` of it), ``worse_than_line``, ``refit``
        (the best ones' fits on all the data failed their guards), ``skipped`` (nothing
        validated within the budget), ``failed`` (every candidate failed); ``ok`` when it has
        a winner.
    """
    if result["winner"] is not None:
        return "ok"
    scored = [r for r in result["ranking"] if "error" not in r]
    if not scored:
        return "skipped" if result.get("skipped") and not result["ranking"] else "failed"
    if all(max(r["cv_r2"], r["cv_linear_r2"]) < MIN_EXPLAINED for r in scored):
        return "no_signal"  # nothing explains the position, not even the straight line
    if any(r["verdict"] == "ok" and not r["guard_failed"] for r in scored):
        return "refit"
    if all(max(r["cv_r2"], r["cv_linear_r2"]) < MIN_USABLE for r in scored):
        return "poor"  # some signal, but no candidate (nor the line) is usable held out
    return "worse_than_line"


def explain_choice(result: dict, n_folds: int) -> list[str]:
    """The guided fit's three lines: what won and why, its held-out score with the protocol
    named, the runner-up and why not the others.

    Parameters
    ----------
    result : dict
        What the selection returned, with a winner.
    n_folds : int
        How many folds the held-out score is the mean of.

    Returns
    -------
    list of str
        The three lines.
    """
    w = result["winner"]
    usable = [r for r in result["ranking"] if "error" not in r and not r["guard_failed"]
              and r["verdict"] == "ok" and r is not w]
    first = (f"chose {w['model']} (size {w['size']}, {w['mode']} mode, centring "
             f"{w['center']}): the best held-out score of {len(result['ranking'])} "
             f"candidates validated, beating its straight line")
    oracle = "" if w["cv_r2_oracle"] is None else f", oracle {w['cv_r2_oracle']:.4f}"
    second = (f"  deployable R² {w['cv_r2']:.4f} on held-out data ({result['protocol']}, mean "
              f"over {n_folds} fold(s); worst fold {w['cv_r2_min']:.4f}); straight line "
              f"{w['cv_linear_r2']:.4f}{oracle}")
    runner = usable[0] if usable else None
    others = [_why_not(r) for r in result["ranking"] if r is not w and r is not runner]
    skipped = [":".join(label.split(":")[:2]) for label, _ in result["skipped"]]
    third = ((f"  runner-up {_short(runner)} {runner['cv_r2']:.4f}" if runner
              else "  no runner-up usable")
             + (f"; then {', '.join(others)}" if others else "")
             + (f"; skipped for the time budget: {', '.join(skipped)}" if skipped else ""))
    return [first, second, third]


def _why_not(row: dict) -> str:
    """A losing candidate, its held-out R² and, if it could not have won anyway, why."""
    if "error" in row:
        return f"{_short(row)} failed ({row['error'].split(':')[0]})"
    if row.get("error_final"):
        return f"{_short(row)} {row['cv_r2']:.4f} (its fit on all the data failed its guards)"
    if row["guard_failed"] or row["verdict"] != "ok":
        return (f"{_short(row)} {row['cv_r2']:.4f} "
                f"({(row['guard_failed'] or row['verdict']).replace('_', ' ')})")
    return f"{_short(row)} {row['cv_r2']:.4f}"


def _short(row: dict) -> str:
    return f"{row['model']}:{row['size']}"
