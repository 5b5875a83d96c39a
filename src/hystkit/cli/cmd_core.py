"""Core subcommands: simulate-sensor, fit, compensate, evaluate, demo (issue 2)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..compensation import (
    CENTERS,
    MODES,
    evaluate,
    fit_compensator,
    load_compensator,
    save_compensator,
)
from ..io import check_output_path, read_recording, write_json, write_recording
from ..models import FAMILIES, get_family
from ..sensors import simulate_experiment
from ..signals import EXPERIMENTS
from ._common import UsageError, positive_int, slope_cap
from .cmd_preprocess import add_simulation_options, run_raw_simulation, sensor_from_args

__all__ = ["register"]


def _simulate_sensor(args: argparse.Namespace) -> int:
    if args.raw:
        return run_raw_simulation(args)
    check_output_path(args.out, args.force)
    rec = simulate_experiment(args.excitation, seed=args.seed, sensor=sensor_from_args(args))
    write_recording(rec, args.out, force=args.force)
    print(f"wrote {args.out}: {EXPERIMENTS[args.excitation].description}, seed {args.seed}, "
          f"{rec.n_samples} samples at {rec.fs:g} Hz")
    return 0


def _fit(args: argparse.Namespace) -> int:
    check_output_path(args.out, args.force)
    family = get_family(args.model)
    options = {} if args.slope_cap is None else {"slope_cap": args.slope_cap}
    if options and args.model != "mpl":
        raise UsageError(f"--slope-cap applies to the mpl model only, not {args.model!r}")
    rec = read_recording(args.data)
    size = family.default_size if args.cells is None else args.cells
    print(f"fitting {args.model} ({family.size_help}: {size}, {args.mode} mode, centring: "
          f"{args.center}) on {args.data}: {rec.n_samples} samples at {rec.fs:g} Hz ...",
          flush=True)
    comp = fit_compensator(rec, size, model=args.model, mode=args.mode, center=args.center,
                           **options)
    save_compensator(comp, args.out, force=args.force)
    info = comp.fit_info
    print(f"done in {info['fit_seconds']:.2f} s: SSE {info['cost']:.4g} (normalised), "
          f"{'converged' if info['converged'] else 'NOT converged'} ({info['message']})")
    print(f"  parameters: {comp.params.to_dict()}")
    print(f"wrote {args.out}")
    return 0


def _compensate(args: argparse.Namespace) -> int:
    check_output_path(args.out, args.force)
    comp = load_compensator(args.model)
    rec = read_recording(args.data, need_position=False)
    estimate = comp.estimate(rec)
    write_recording(rec, args.out, extra={"position_estimate": estimate}, force=args.force)
    print(f"wrote {args.out}: {rec.n_samples} samples with column 'position_estimate' [mm] "
          f"(centring: {comp.center})")
    _warn_if_extrapolating(comp.extrapolated_fraction(rec), args.data)
    return 0


def _warn_if_extrapolating(fraction: float | None, data: Path) -> None:
    """Say so when the compensator runs outside the sensor range it was trained on."""
    if fraction:
        print(f"hystkit: warning: {data}: {100 * fraction:.1f} % of the samples lie outside the "
              f"sensor range the compensator was trained on; its estimate there is an "
              f"extrapolation", file=sys.stderr)


def _evaluate(args: argparse.Namespace) -> int:
    if args.json is not None:
        check_output_path(args.json, args.force)
    comp = load_compensator(args.model)
    scores = evaluate(comp, read_recording(args.data))
    _warn_if_extrapolating(scores["extrapolated_fraction"], args.data)
    print(f"{args.data} with {args.model} (centring: {scores['center']}, "
          f"{scores['n_samples']} samples)")
    print(f"{'':<22}{comp.model:>10}{'straight line':>15}")
    for key, label in (("r2", "R²"), ("e_rms_pct", "e_rms %"), ("e_max_pct", "e_max %"),
                       ("sinad_db", "SINAD dB"), ("loop_area", "loop area %")):
        a, b = scores[key], scores[f"linear_{key}"]
        print(f"{label:<22}{_fmt(a):>10}{_fmt(b):>15}")
    print(f"{'sensor loop area %':<22}{_fmt(scores['sensor_loop_area']):>10}")
    if args.json is not None:
        write_json(scores, args.json, force=args.force)
        print(f"wrote {args.json}")
    return 0


def _fmt(x: float | None) -> str:
    return "n/a" if x is None else f"{x:.4f}"


def _demo(args: argparse.Namespace) -> int:
    # Imported here so the other subcommands do not pay for loading matplotlib.
    from ..reports import DOCUMENT_TABLE_5_5, format_table, run_demo

    out = args.out or Path(f"hystkit-demo-{time.strftime('%Y%m%d-%H%M%S')}")
    print(f"hystkit demo: virtual sensor, four experiments, {args.cells}-cell mPL compensator "
          f"fitted on one recording and scored on another (direct mode, centring: recording)")
    t0 = time.perf_counter()
    result = run_demo(out, n_cells=args.cells, force=args.force, raw=args.raw)
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
          f"time_series.png{', raw_path.json' if raw else ''} "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0


def _print_raw_path(raw: dict) -> None:
    from ..reports import format_table  # lazily, as in _demo

    print()
    print(format_table({f"{raw['excitation']} raw": raw["metrics"]},
                       f"Raw path: scope files at {raw['scope_rate_hz']:g} Hz -> preprocess -> "
                       f"fit -> evaluate (cf. the {raw['excitation']} row above)"))
    trip = raw["round_trip"]["validation"]
    print(f"  decoded vs true: position max error {trip['position_max_error_um']:.2f} um "
          f"({trip['position_max_error_counts']:.2f} counts), dR/R rms error "
          f"{trip['sensor_rms_error']:.1e}, {trip['n_illegal']} illegal of {trip['n_edges']} "
          f"encoder transitions")


def register(sub: argparse._SubParsersAction) -> None:
    """Add this module's subcommands to the ``hystkit`` parser."""
    p = sub.add_parser("simulate-sensor", help="record an experiment on the virtual sensor")
    p.add_argument("--excitation", choices=sorted(EXPERIMENTS), required=True)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", type=Path, required=True, help="CSV or Parquet file to write")
    add_simulation_options(p)
    p.set_defaults(run=_simulate_sensor)

    p = sub.add_parser("fit", help="fit a compensator to a recording")
    p.add_argument("data", type=Path, help="recording: time, position, sensor (CSV/Parquet/.mat)")
    p.add_argument("--model", choices=sorted(FAMILIES), default="mpl",
                   help="; ".join(f"{f.name}: {f.title}" for f in FAMILIES.values()))
    p.add_argument("--cells", "--size", type=positive_int, default=None,
                   help="model size: " + "; ".join(f"{f.name}: {f.size_help} (default "
                                                    f"{f.default_size})"
                                                    for f in FAMILIES.values()))
    p.add_argument("--mode", choices=MODES, default="direct",
                   help="direct: fit sensor->position (paper 9.2); inverse: fit "
                        "position->sensor and invert it (paper 9.1)")
    p.add_argument("--center", choices=CENTERS, default="recording",
                   help="whose mean is removed: each recording's own (hides drift), the "
                        "fitting recording's, or none")
    p.add_argument("--slope-cap", type=slope_cap, default=None,
                   help="mpl only: Euler stability cap f'·dt of the cell resistors, in (0, 2) "
                        "(default 1)")
    p.add_argument("--out", type=Path, required=True, help="model JSON file to write")
    p.set_defaults(run=_fit)

    p = sub.add_parser("compensate", help="add a position_estimate column to a recording")
    p.add_argument("model", type=Path)
    p.add_argument("data", type=Path)
    p.add_argument("--out", type=Path, required=True)
    p.set_defaults(run=_compensate)

    p = sub.add_parser("evaluate", help="score a compensator on a recording")
    p.add_argument("model", type=Path)
    p.add_argument("data", type=Path)
    p.add_argument("--json", type=Path, help="also write the scores to this JSON file")
    p.set_defaults(run=_evaluate)

    p = sub.add_parser("demo", help="the main job on the built-in virtual sensor")
    p.add_argument("--out", type=Path, help="output folder (default: a new timestamped one)")
    p.add_argument("--cells", type=positive_int, default=3,
                   help="mPL cells (default 3: 11 parameters, as the document's model)")
    p.add_argument("--raw", action="store_true",
                   help="also run the lab chain on raw scope files: simulate-sensor --raw -> "
                        "preprocess -> fit -> evaluate (sine, 50 kHz; about 10 s more)")
    p.set_defaults(run=_demo)

