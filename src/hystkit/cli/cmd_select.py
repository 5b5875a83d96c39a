"""``hystkit select``: choose family x size x mode by cross-validation on training data."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ._common import (
    GUARD_EXIT,
    UsageError,
    add_read_options,
    deferred,
    failures_exit,
    positive_int,
    read_options,
)
from .cmd_compare import _models, add_parallel_options, executor_for

__all__ = ["register"]

SELECTION_FILES = ("selection.json", "selection.csv", "selection.png")


def _centers(text: str) -> list[str]:
    from ..compensation import CENTERS

    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in CENTERS]
    if unknown or not names:
        raise UsageError(f"--centers: unknown centring(s) {', '.join(unknown) or '(none)'}; "
                         f"known: {', '.join(CENTERS)}")
    return names


def _select(args: argparse.Namespace) -> int:
    import pandas as pd  # only this command needs it and matplotlib

    from ..compensation import MODEL_SUFFIXES, save_compensator
    from ..io import (
        atomic_folder,
        check_output_folder,
        check_output_path,
        read_recording,
        write_json,
    )
    from ..parallel import loading_meanwhile
    from ..reports import FIGURE_MODULES, candidates, folds, plot_selection, select_model

    check_output_path(args.out, args.force, inputs=args.data, formats=MODEL_SUFFIXES,
                      what="a model file")
    report = args.report or args.out.with_name(args.out.stem + "-selection")
    check_output_folder(report, SELECTION_FILES, args.force, inputs=args.data)
    recs = [read_recording(path, options=read_options(args, path)) for path in args.data]
    cands = candidates(_models(args.models), _centers(args.centers))
    t0 = time.perf_counter()
    print(f"selecting among {len(cands)} candidates on {', '.join(map(str, args.data))} "
          f"(deployable held-out R², "
          f"{'leave-one-recording-out' if len(recs) > 1 else 'blocked time folds'})")
    n_pieces = len(cands) * len(folds(recs))
    # while the workers run the map, this process loads the figure's matplotlib and numba for
    # the winner's refit
    with executor_for(args, n_pieces) as executor, \
            loading_meanwhile(executor, FIGURE_MODULES, numba_ready=True):
        result = select_model(recs, cands, executor=executor, progress=print)
    rows = result["ranking"]
    print(f"{'candidate':<32}{'cv R²':>8}{'min':>8}{'oracle':>8}{'line':>8}{'params':>7}"
          f"{'AIC':>10}{'BIC':>10}  guards")
    for r in rows:
        if "error" in r:
            print(f"{r['candidate']:<32}  FAILED: {r['error']}")
            continue
        print(f"{r['candidate']:<32}{r['cv_r2']:>8.4f}{r['cv_r2_min']:>8.4f}"
              f"{r['cv_r2_oracle']:>8.4f}{r['cv_linear_r2']:>8.4f}{r['n_params']:>7d}"
              f"{r['aic']:>10.0f}{r['bic']:>10.0f}  {r['guard_failed'] or 'ok'}")
    summary = {"winner": result["winner"], "folds": result["folds"], "ranking": rows,
               "seconds": time.perf_counter() - t0, "model_file": str(args.out)}
    # The report folder is published only after the winner's model file was: a failure on the
    # way leaves neither (the model file alone only if the folder's rename itself fails).
    with atomic_folder(report, args.force, SELECTION_FILES) as tmp:
        write_json(summary, tmp / "selection.json")
        pd.DataFrame([{k: v for k, v in r.items() if k != "fold_status"}
                      for r in rows]).to_csv(tmp / "selection.csv", index=False)
        plot_selection(rows).savefig(tmp / "selection.png", dpi=110)
        if result["winner"] is not None:
            save_compensator(result["compensator"], args.out, force=args.force)
    print(f"wrote {report / 'selection.json'}, .csv, .png ({summary['seconds']:.1f} s)")
    if result["winner"] is None:
        print("hystkit: no candidate passed its guards; no model written", file=sys.stderr)
        return GUARD_EXIT
    w = result["winner"]
    print(f"winner: {w['candidate']} (held-out deployable R² {w['cv_r2']:.4f}, oracle "
          f"{w['cv_r2_oracle']:.4f}, line {w['cv_linear_r2']:.4f}); wrote {args.out}")
    return failures_exit([r["candidate"] for r in rows if "error" in r], "candidate(s)")


def _default_center() -> str:
    from ..compensation import DEFAULT_CENTER

    return DEFAULT_CENTER


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``select``."""
    p = sub.add_parser("select", help="choose model family, size and mode by cross-validation "
                                      "on training recordings")
    p.add_argument("data", type=Path, nargs="+", help="training recording(s), one rate")
    p.add_argument("--out", type=Path, required=True, help="model JSON file of the winner")
    p.add_argument("--report", type=Path,
                   help="folder for selection.json/.csv/.png (default: OUT's name + -selection)")
    p.add_argument("--models", help="comma-separated families (default: all)")
    deferred(p.add_argument("--centers"), default=_default_center,
             help=lambda: f"comma-separated centrings to try (default {_default_center()})")
    add_read_options(p)
    add_parallel_options(p)
    # the option's name before issue 13; --workers N does the same
    p.add_argument("--jobs", type=positive_int, dest="workers", help=argparse.SUPPRESS)
    p.set_defaults(run=_select)
