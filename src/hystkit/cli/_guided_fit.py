"""``hystkit fit --model auto``: a guided first fit (issue 27.5).

A short, fixed list of small candidates goes through ``select``'s machinery (the same folds,
score, verdict, refit of the winner and band: :func:`hystkit.studies.select_model`) under a
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

import argparse
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial

from ._common import GUARD_EXIT, UsageError, next_step, read_training_files, say_next
from ._fit_report import print_band, print_parameters, print_standard_errors, units_label
from ._inputs import check_inputs_exist

__all__ = ["DEFAULT_BUDGET", "GUIDED", "GUIDED_HELP", "GUIDED_MODEL", "SHORT_LIST", "guided_candidates", "guided_select",
           "model_options_given", "run_guided_fit", "selection_status"]

# fit's --model value for the guided fit, its default (issue 27.5)
GUIDED_MODEL = GUIDED = "auto"
GUIDED_HELP = ("mpl with 1, 2 and 3 cells, mpl-poly, pi and pl, each fitted and scored on "
               "held-out data as select does, the best usable one written with its band and "
               "the choice explained in three lines (about 15-30 s for 10,000 samples on 2 "
               "cores)")
# Seconds for the whole guided fit (issue 27.5: <= 60 s for 10,000 samples on 2 cores)
DEFAULT_BUDGET = 60.0
# (family, size), see the module docstring for why these
SHORT_LIST = (("mpl", 1), ("pi", 10), ("mpl-poly", 1), ("mpl", 2), ("pl", 1), ("mpl", 3))
# Share of the budget in which validation pieces may start; the rest is for the pieces still
# running and the winner's refit and band (measured: 20-35 % of the whole on 10,000 samples)
VALIDATION_SHARE = 0.5
SKIPPED = "not validated: its turn came after the time budget's validation share"
# fit's options that name one model's structure, start or cost: refused with --model auto
_MODEL_OPTIONS = {"cells": ("--cells", None), "slope_cap": ("--slope-cap", None),
                  "p": ("--p", None), "m": ("--m", None), "s": ("--s", None),
                  "init": ("--init", None), "no_limit": ("--no-limit", False),
                  "weight_sum_max": ("--weight-sum-max", None), "loss": ("--loss", "linear"),
                  "f_scale": ("--f-scale", None), "weights": ("--weights", None)}


def guided_candidates(recordings: Sequence, mode: str = "direct", center: str = "fit"
                      ) -> list:
    """`SHORT_LIST` as `hystkit.compensation.Candidate`, cheapest first, without those the
    smallest fold cannot fit (too few samples per parameter) or that have no inverse (`mode`
    ``"inverse"``)."""
    from ..compensation import Candidate, fits_in, folds
    from ..models import get_family
    from ..parallel import fit_cost

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
    from ..compensation import check_fitting_data, folds, protocol
    from ..parallel import SerialExecutor, fit_cost
    from ..studies import select_model

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
    """Why a selection has no winner, as a `next_step` status: ``no_signal`` (no candidate
    explains the position), ``worse_than_line``, ``refit`` (the best ones' fits on all the data
    failed their guards), ``skipped`` (nothing validated within the budget), ``failed``
    (every candidate failed); ``ok`` when it has one."""
    if result["winner"] is not None:
        return "ok"
    scored = [r for r in result["ranking"] if "error" not in r]
    if not scored:
        return "skipped" if result.get("skipped") and not result["ranking"] else "failed"
    from ..compensation import MIN_EXPLAINED

    if all(max(r["cv_r2"], r["cv_linear_r2"]) < MIN_EXPLAINED for r in scored):
        return "no_signal"  # nothing explains the position, not even the straight line
    if any(r["verdict"] == "ok" and not r["guard_failed"] for r in scored):
        return "refit"
    return "worse_than_line"


def explain(result: dict, n_folds: int) -> list[str]:
    """The guided fit's three lines: what won and why, its held-out score with the protocol
    named, the runner-up and why not the others."""
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


def model_options_given(args: argparse.Namespace) -> list[str]:
    """The options of one named model on `args` (``--cells``, ``--init``, ``--loss``, ...)."""
    return [option for dest, (option, unset) in _MODEL_OPTIONS.items()
            if getattr(args, dest, unset) != unset]


def _refuse_model_options(args: argparse.Namespace) -> None:
    given = model_options_given(args)
    if given:
        raise UsageError(f"{given[0]} applies to a named model (e.g. --model mpl {given[0]} "
                         f"...); --model {GUIDED} tries its own short list")


def run_guided_fit(args: argparse.Namespace) -> int:
    """``hystkit fit DATA --model auto --out MODEL``: the command's side of `guided_select`."""
    _refuse_model_options(args)
    check_inputs_exist(args.data)  # a misspelt name is refused before the heavy imports
    from ..compensation import MODEL_SUFFIXES, folds, save_compensator
    from ..io import (
        check_output_path,
        training_reading,
        training_units,
    )
    from ..parallel import loading_meanwhile, open_executor

    check_output_path(args.out, args.force, inputs=args.data, formats=MODEL_SUFFIXES,
                      what="a model file")
    t0, budget = time.perf_counter(), args.budget or DEFAULT_BUDGET
    reading, recs = read_training_files(args)
    units = training_units(recs)
    remembered, not_remembered = training_reading(reading, args.data, units)
    n_folds = len(folds(recs))
    print(f"guided fit on {', '.join(map(str, args.data))}: "
          f"{sum(r.n_samples for r in recs)} samples at {recs[0].fs:g} Hz{units_label(recs[0])}"
          f"; trying {', '.join(f'{m}:{s}' for m, s in SHORT_LIST)} ({args.mode} mode, "
          f"centring {args.center}), scored on held-out data, within {budget:g} s",
          flush=True)
    options = {"tare_seconds": args.tare_seconds, "track_seconds": args.track_seconds}
    with open_executor(n_pieces=len(SHORT_LIST) * n_folds) as executor, \
            loading_meanwhile(executor, numba_ready=True):
        result = guided_select(recs, budget=budget, mode=args.mode, center=args.center,
                               executor=executor, progress=print, **options)
    for label, reason in result["skipped"]:
        print(f"  {label}: skipped: {reason}")
    seconds = time.perf_counter() - t0
    if result["winner"] is None:
        status = selection_status(result)
        sys.stdout.flush()  # the progress lines before the refusal
        print(f"hystkit: fit: no usable model among {len(SHORT_LIST)} candidates, none "
              f"written ({seconds:.1f} s): {status.replace('_', ' ')}: {result['refusal']}",
              file=sys.stderr)
        best = next((r for r in result["ranking"] if "error" not in r), None)
        say_next(next_step(status, command="guided", model=best and best["model"],
                           size=best and best["size"]))
        return GUARD_EXIT
    comp = result["compensator"]
    lines = explain(result, n_folds)
    info = {**comp.fit_info, "selection": lines}
    if units:
        info["units"] = units
    band = comp.band
    if band is not None and args.no_band:
        band, info["band"] = None, "no band: --no-band"
    elif band is not None and args.level != band.level:
        band = replace(band, level=args.level)
    comp = replace(comp, band=band, fit_info=info, reading=remembered)
    save_compensator(comp, args.out, force=args.force)
    print("\n".join(lines))
    for caveat in result["caveats"]:
        print(f"  note: {caveat}")
    print_band(comp)
    print_parameters(comp, info.get("standard_errors"))
    print_standard_errors(info.get("standard_errors"))
    print(f"  training R² {info['training_r2']:.4f}, straight line "
          f"{info['training_linear_r2']:.4f}; sensor polarity {comp.polarity:+g}")
    for note in [*(info.get("at_model_limits") or ()), *(info.get("redundant") or ()),
                 *filter(None, [not_remembered])]:
        print(f"  note: {note}")
    print(f"wrote {args.out} ({seconds:.1f} s)")
    print(f"  status: ok ({info['status_message']})")
    return 0
