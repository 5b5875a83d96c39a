"""``hystkit select``: choose family x size x mode x centring, validated the way it is used."""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import pandas as pd

from ..compensation import CENTERS, MODEL_SUFFIXES, folds, protocol, save_compensator
from ..io import (
    atomic_folder,
    check_output_folder,
    check_output_path,
    read_recording,
    training_reading,
    write_json,
)
from ..parallel import loading_meanwhile
from ..studies import (
    FIGURE_MODULES,
    candidates,
    plot_selection,
    select_model,
    selection_status,
    text_table,
)
from ._common import GUARD_EXIT, UsageError, say_next
from ._many_models import ParallelOptions, models_from, open_executor_for
from ._next_step import next_step
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["SelectOptions", "run_select"]

SELECTION_FILES = ("selection.json", "selection.csv", "selection.png")


def _centers(text: str) -> list[str]:
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in CENTERS]
    if unknown or not names:
        raise UsageError(f"--centers: unknown centring(s) {', '.join(unknown) or '(none)'}; "
                         f"known: {', '.join(CENTERS)}")
    return names


@dataclass(frozen=True)
class SelectOptions:
    """``hystkit select``'s options, as parsed."""

    data: tuple[Path, ...]
    reader: Reader  # how each of `data` is read
    parallel: ParallelOptions
    out: Path
    report: Path | None
    models: str | None
    centers: str
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> SelectOptions:
        """The options of a parsed ``select`` command line."""
        return cls(tuple(args.data), Reader(given_read_options(args)),
                   ParallelOptions.from_args(args), args.out, args.report, args.models,
                   args.centers, args.force)


def run_select(args: argparse.Namespace) -> int:
    """``hystkit select``: family, size, mode and centring chosen on held-out data."""
    return select(SelectOptions.from_args(args))


def select(opts: SelectOptions) -> int:
    """Choose on held-out data, write the winner's model file and the selection report."""
    check_output_path(opts.out, opts.force, inputs=opts.data, formats=MODEL_SUFFIXES,
                      what="a model file")
    report = opts.report or opts.out.with_name(opts.out.stem + "-selection")
    check_output_folder(report, SELECTION_FILES, opts.force, inputs=opts.data)
    reading, recs = [], []
    for path in opts.data:
        reading.append(opts.reader.options(path))
        recs.append(read_recording(path, options=reading[-1]))
    units = {name: unit for name, unit in recs[0].units if all(r.unit(name) == unit for r in recs)}
    remembered, not_remembered = training_reading(reading, opts.data, units)
    fold_list = folds(recs)
    fit_samples = min((f.n_train for f in fold_list), default=0)
    cands = candidates(models_from(opts.models), _centers(opts.centers), fit_samples=fit_samples,
                       dt=recs[0].dt)
    t0 = time.perf_counter()
    print(f"selecting among {len(cands)} candidates on {', '.join(map(str, opts.data))} "
          f"(deployable R² on held-out data: {protocol(recs)})")
    # while the workers run the map, this process loads the figure's matplotlib and numba for
    # the winner's refit
    with open_executor_for(opts.parallel, len(cands) * len(fold_list)) as executor, \
            loading_meanwhile(executor, FIGURE_MODULES, numba_ready=True):
        result = select_model(recs, cands, executor=executor, progress=print)
    rows = result["ranking"]
    scored = [r for r in rows if "error" not in r]
    print(text_table(
        ("candidate", "held-out R²", "min", "line", "oracle", "params", "AIC", "BIC", "verdict"),
        [(r["candidate"], r["cv_r2"], r["cv_r2_min"], r["cv_linear_r2"], r["cv_r2_oracle"],
          r["n_params"], r["aic"], r["bic"],
          (r["guard_failed"] or r["verdict"]).replace("_", " ")) for r in scored],
        digits=(0, 4, 4, 4, 4, 0, 1, 1, 0)))
    print(f"  held-out R²: {result['protocol']}, mean over {len(fold_list)} fold(s); line: the "
          f"straight line fitted on the same training samples; oracle: the paper's protocol, "
          f"n/a for tare/track (it replaces the offset being judged)")
    for r in rows:
        if "error" in r:
            print(f"  {r['candidate']}: FAILED: {r['error']}")
        elif r.get("error_final"):
            print(f"  {r['candidate']}: not taken: {r['error_final']}")
    for caveat in result["caveats"]:
        print(f"  note: {caveat}")
    summary = {"winner": result["winner"], "protocol": result["protocol"],
               "caveats": result["caveats"], "refusal": result["refusal"],
               "folds": result["folds"], "ranking": rows,
               "seconds": time.perf_counter() - t0, "model_file": str(opts.out)}
    # The report folder is published only after the winner's model file was: a failure on the
    # way leaves neither (the model file alone only if the folder's rename itself fails).
    with atomic_folder(report, opts.force, SELECTION_FILES) as tmp:
        write_json(summary, tmp / "selection.json")
        pd.DataFrame([{k: v for k, v in r.items() if k != "fold_status"}
                      for r in rows]).to_csv(tmp / "selection.csv", index=False)
        plot_selection(rows).savefig(tmp / "selection.png", dpi=110)
        if result["winner"] is not None:
            # later commands read files of the training files' layout as these were read
            save_compensator(replace(result["compensator"], reading=remembered), opts.out,
                             force=opts.force)
    print(f"wrote {report / 'selection.json'}, .csv, .png ({summary['seconds']:.1f} s)")
    if result["winner"] is None:
        sys.stdout.flush()  # the table before the refusal
        print(f"hystkit: select: no usable model, none written: {result['refusal']}",
              file=sys.stderr)
        best = next((r for r in rows if "error" not in r), None)
        say_next(next_step(selection_status(result), command="select",
                           model=best and best["model"], size=best and best["size"]))
        return GUARD_EXIT
    if not_remembered:
        print(f"  note: {not_remembered}")
    w = result["winner"]
    oracle = "" if w["cv_r2_oracle"] is None else f", oracle {w['cv_r2_oracle']:.4f}"
    print(f"winner: {w['candidate']} (deployable R² {w['cv_r2']:.4f} on held-out data, "
          f"{result['protocol']}; straight line {w['cv_linear_r2']:.4f}{oracle}); "
          f"wrote {opts.out}")
    return 0
