"""``hystkit fit --model auto``: the command's side of the guided first fit (issue 27.5):
reading the recordings, the progress and the three lines that explain the choice, the model
file. The selection itself is `hystkit.studies.guided_select`."""

from __future__ import annotations

import sys
import time
from dataclasses import replace

from ..compensation import MODEL_SUFFIXES, folds, save_compensator
from ..io import check_output_path, training_reading, training_units
from ..parallel import loading_meanwhile, open_executor
from ..studies._guided import (
    DEFAULT_BUDGET,
    SHORT_LIST,
    explain_choice,
    guided_select,
    selection_status,
)
from ._common import GUARD_EXIT, UsageError, say_next
from ._core_options import GUIDED_MODEL, model_options_given
from ._fit_checks import FitOptions
from ._fit_report import FitReport, units_label
from ._inputs import check_inputs_exist
from ._next_step import next_step

__all__ = ["run_guided_fit"]


def _refuse_model_options(opts: FitOptions) -> None:
    given = model_options_given(opts)
    if given:
        raise UsageError(f"{given[0]} applies to a named model (e.g. --model mpl {given[0]} "
                         f"...); --model {GUIDED_MODEL} tries its own short list")


def run_guided_fit(opts: FitOptions) -> int:
    """``hystkit fit DATA --model auto --out MODEL``: the command's side of `guided_select`."""
    _refuse_model_options(opts)
    check_inputs_exist(opts.data)
    check_output_path(opts.out, opts.force, inputs=opts.data, formats=MODEL_SUFFIXES,
                      what="a model file")
    t0, budget = time.perf_counter(), opts.budget or DEFAULT_BUDGET
    reading, recs = opts.reader.training_files(opts.data)
    units = training_units(recs)
    remembered, not_remembered = training_reading(reading, opts.data, units)
    n_folds = len(folds(recs))
    print(f"guided fit on {', '.join(map(str, opts.data))}: "
          f"{sum(r.n_samples for r in recs)} samples at {recs[0].fs:g} Hz{units_label(recs[0])}"
          f"; trying {', '.join(f'{m}:{s}' for m, s in SHORT_LIST)} ({opts.mode} mode, "
          f"centring {opts.center}), scored on held-out data, within {budget:g} s",
          flush=True)
    options = {"tare_seconds": opts.tare_seconds, "track_seconds": opts.track_seconds}
    with open_executor(n_pieces=len(SHORT_LIST) * n_folds) as executor, \
            loading_meanwhile(executor, numba_ready=True):
        result = guided_select(recs, budget=budget, mode=opts.mode, center=opts.center,
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
    lines = explain_choice(result, n_folds)
    info = {**comp.fit_info, "selection": lines}
    if units:
        info["units"] = units
    band = comp.band
    if band is not None and opts.no_band:
        band, info["band"] = None, "no band: --no-band"
    elif band is not None and opts.level != band.level:
        band = replace(band, level=opts.level)
    comp = replace(comp, band=band, fit_info=info, reading=remembered)
    save_compensator(comp, opts.out, force=opts.force)
    print("\n".join(lines))
    for caveat in result["caveats"]:
        print(f"  note: {caveat}")
    print(FitReport.of(comp, criteria=False, notes=tuple(filter(None, [not_remembered]))).text())
    print(f"wrote {opts.out} ({seconds:.1f} s)")
    print(f"  status: ok ({info['status_message']})")
    return 0
