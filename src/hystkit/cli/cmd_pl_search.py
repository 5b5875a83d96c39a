"""``hystkit pl-search DATA_FIT``: exhaustive N, p, M, S search of the Power-Law model (table 5.1)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..io import check_output_path, read_recording, write_json
from ..models.pl import DEFAULT_GRID, format_search_table, structural_search

__all__ = ["register"]


def _floats(text: str) -> tuple[float, ...]:
    try:
        return tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") \
            from None


def _ints(text: str) -> tuple[int, ...]:
    values = _floats(text)
    if any(v != int(v) or v < 1 for v in values):
        raise argparse.ArgumentTypeError(f"expected comma-separated positive integers, got {text!r}")
    return tuple(int(v) for v in values)


def _search(args: argparse.Namespace) -> int:
    if args.json is not None:
        check_output_path(args.json, args.force)
    rec = read_recording(args.data)
    u, y = ((rec.position, rec.sensor) if args.direction == "position-to-sensor"
            else (rec.sensor, rec.position))
    grid = {"n": args.n, "p": args.p, "m": args.m, "s": args.s}
    rows = structural_search(u, y, rec.dt, grid)
    print(f"{args.data}: Power-Law structural search, {args.direction}, {u.size} samples, "
          f"dt = {rec.dt:g} s (errors eq. 5.11 on data normalised by eq. 5.10)")
    print(format_search_table(rows))
    best = min(rows, key=lambda r: r["e_rms_pct"])
    print(f"best: N = {best['n_cells']}, p = {best['power']:g}, M = {best['n_basis']}, "
          f"S = {best['smoothing']:g} (e_rms {best['e_rms_pct']:.3f} %)")
    if args.json is not None:
        write_json({"data": str(args.data), "direction": args.direction, "grid": grid,
                    "rows": rows}, args.json, force=args.force)
        print(f"wrote {args.json}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``pl-search`` subcommand to the ``hystkit`` parser."""
    p = sub.add_parser("pl-search", help="exhaustive N, p, M, S search of the Power-Law model "
                                         "(sec. 2.2, table 5.1)")
    p.add_argument("data", type=Path, help="fitting recording (time, position, sensor)")
    p.add_argument("--n", type=_ints, default=DEFAULT_GRID["n"], help="cell counts N")
    p.add_argument("--p", type=_floats, default=DEFAULT_GRID["p"], help="powers p (> 1)")
    p.add_argument("--m", type=_ints, default=DEFAULT_GRID["m"],
                   help="numbers M of output basis functions")
    p.add_argument("--s", type=_floats, default=DEFAULT_GRID["s"], help="smoothing weights S")
    p.add_argument("--direction", choices=("position-to-sensor", "sensor-to-position"),
                   default="position-to-sensor",
                   help="model the sensor (the document's toolbox, default) or a direct "
                        "compensator")
    p.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    p.set_defaults(run=_search)
