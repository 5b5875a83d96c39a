"""``hystkit pl-search DATA_FIT``: exhaustive N, p, M, S search of the Power-Law model (table 5.1)."""

from __future__ import annotations

import argparse

from ..compensation import check_fitting_data
from ..io import check_output_path, write_json
from ..models.pl import FAMILY, PlStructure, format_search_table, structural_search
from ._many_models import ParallelOptions, open_executor_for, say_where
from ._reading import read_recording_args

__all__ = ["run_pl_search"]


def run_pl_search(args: argparse.Namespace) -> int:
    """``hystkit pl-search``: the Power-Law model's structural search on one recording."""
    parallel = ParallelOptions.from_args(args)
    if args.json is not None:
        check_output_path(args.json, args.force, inputs=[args.data])
    rec = read_recording_args(args, args.data)
    # What `fit` demands (samples per parameter, a position and sensor that move), for the
    # largest structure of the grid: two samples "fit" every structure with e_rms 0.000 %.
    check_fitting_data([rec], FAMILY, PlStructure(n_cells=max(args.n), n_basis=max(args.m),
                                                  dt=rec.dt))
    u, y = ((rec.position, rec.sensor) if args.direction == "position-to-sensor"
            else (rec.sensor, rec.position))
    grid = {"n": args.n, "p": args.p, "m": args.m, "s": args.s}
    n_pieces = len(args.n) * len(args.p) * len(args.m) * len(args.s)
    with open_executor_for(parallel, n_pieces) as executor:
        say_where(executor, n_pieces)
        rows = structural_search(u, y, rec.dt, grid, executor=executor)
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
