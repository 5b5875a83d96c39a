"""``hystkit simulate-sensor`` and ``hystkit demo``: the built-in virtual sensor's
recordings, and the main job run on them."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from ..compensation import DEFAULT_CENTER
from ..io import check_output_path, write_recording
from ..sensors import occasional_references, simulate_experiment, with_gain_drift
from ..signals import EXPERIMENTS
from ..studies import DOCUMENT_TABLE_5_5, format_table
from ..studies import run_demo as demo_study
from ._common import UsageError, check_size
from .cmd_preprocess import run_raw_simulation, sensor_from_args

__all__ = ["run_demo", "run_simulate_sensor"]


def run_simulate_sensor(args: argparse.Namespace) -> int:
    """``hystkit simulate-sensor``: one experiment of the virtual sensor, written."""
    if args.raw:
        if args.gain_drift is not None or args.references_every is not None:
            raise UsageError("--gain-drift and --references-every apply to the 40 Hz "
                             "recording, not to --raw")
        return run_raw_simulation(args)
    check_output_path(args.out, args.force)
    rec = simulate_experiment(args.excitation, seed=args.seed, sensor=sensor_from_args(args))
    if args.gain_drift is not None:
        rec = with_gain_drift(rec, args.gain_drift)
    kept, note = {}, ""
    if args.references_every is not None:  # empty cells where unknown: kept, not checked
        kept = {"reference": occasional_references(rec, args.references_every, args.seed)}
        note = f", a 'reference' column (one true position per {args.references_every:g} s)"
    write_recording(rec, args.out, force=args.force, kept=kept)
    drift = "" if args.gain_drift is None else f", sensor gain drift {args.gain_drift:+.1%}"
    print(f"wrote {args.out}: {EXPERIMENTS[args.excitation].description}, seed {args.seed}, "
          f"{rec.n_samples} samples at {rec.fs:g} Hz{drift}{note}")
    return 0


def run_demo(args: argparse.Namespace) -> int:
    """``hystkit demo``: the main job on the virtual sensor, into a new folder."""
    out = args.out or Path(f"hystkit-demo-{time.strftime('%Y%m%d-%H%M%S')}")
    check_size("mpl", args.cells, "--cells")
    print(f"hystkit demo: virtual sensor, four experiments, {args.cells}-cell mPL compensator "
          f"fitted on one recording and scored on another (direct mode, deployable centring: "
          f"{DEFAULT_CENTER}; the paper's oracle centring beside it)")
    t0 = time.perf_counter()
    result = demo_study(out, n_cells=args.cells, force=args.force, raw=args.raw, report=True)
    print()
    print(format_table(result["metrics"], "Validation (fit on seed 1, test on seed 2); cf. "
                       "document table 5.5", DOCUMENT_TABLE_5_5))
    print()
    print(format_table(result["noise_trained"], "Compensator trained on noise, tested on each "
                       "excitation (does compensation generalise?)"))
    raw = result.get("raw_path")
    if raw is not None:
        _print_raw_path(raw)
    print(f"\nwrote {out}/: metrics.json, noise_trained.json, config.json, loops.png, "
          f"time_series.png, report.html{', raw_path.json' if raw else ''} "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0


def _print_raw_path(raw: dict) -> None:
    print()
    print(format_table({f"{raw['excitation']} raw": raw["metrics"]},
                       f"Raw path: scope files at {raw['scope_rate_hz']:g} Hz -> preprocess -> "
                       f"fit -> evaluate (cf. the {raw['excitation']} row above)"))
    trip = raw["round_trip"]["validation"]
    print(f"  decoded vs true: position max error {trip['position_max_error_um']:.2f} um "
          f"({trip['position_max_error_counts']:.2f} counts), dR/R rms error "
          f"{trip['sensor_rms_error']:.1e}, {trip['n_illegal']} illegal of {trip['n_edges']} "
          f"encoder transitions")
