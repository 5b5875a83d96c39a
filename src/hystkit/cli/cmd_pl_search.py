"""``hystkit pl-search DATA_FIT``: exhaustive N, p, M, S search of the Power-Law model (table 5.1)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from ._common import add_read_options, deferred, integer, number, read_recording_args
from .cmd_compare import add_parallel_options, executor_for, say_where

__all__ = ["register"]


def _list(parse: Callable[[str], float], what: str) -> Callable[[str], tuple]:
    """An option type: comma-separated values, each checked by `parse`."""

    def parse_all(text: str) -> tuple:
        try:
            return tuple(parse(v) for v in text.split(","))
        except argparse.ArgumentTypeError as exc:
            raise argparse.ArgumentTypeError(f"expected comma-separated {what}: {exc}") \
                from None

    return parse_all


def _cells(text: str) -> tuple:
    """An option type: comma-separated cell counts up to the family's ``max_size``."""
    from ..models.pl import FAMILY  # numba kernels: only when --n is given

    return _list(integer(1, FAMILY.max_size), f"cell counts 1 to {FAMILY.max_size}")(text)


_cells.__name__ = "parse_all"  # argparse names the type in some messages, as before
_powers = _list(number(1, 100, low_open=True), "powers p in (1, 100]")
_bases = _list(integer(1, 50), "basis counts 1 to 50")
_smoothing = _list(number(0), "smoothing weights >= 0")


def _search(args: argparse.Namespace) -> int:
    from ..compensation import check_fitting_data
    from ..io import check_output_path, write_json
    from ..models.pl import FAMILY, PlStructure, format_search_table, structural_search

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
    with executor_for(args, n_pieces) as executor:
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


def _default_grid(key: str) -> tuple:
    from ..models.pl import DEFAULT_GRID

    return DEFAULT_GRID[key]


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``pl-search`` subcommand to the ``hystkit`` parser."""
    p = sub.add_parser("pl-search", help="exhaustive N, p, M, S search of the Power-Law model "
                                         "(sec. 2.2, table 5.1)")
    p.add_argument("data", type=Path, help="fitting recording (time, position, sensor)")
    deferred(p.add_argument("--n", type=_cells, help="cell counts N"),
             default=lambda: _default_grid("n"))
    deferred(p.add_argument("--p", type=_powers, help="powers p (> 1)"),
             default=lambda: _default_grid("p"))
    deferred(p.add_argument("--m", type=_bases, help="numbers M of output basis functions"),
             default=lambda: _default_grid("m"))
    deferred(p.add_argument("--s", type=_smoothing, help="smoothing weights S (>= 0)"),
             default=lambda: _default_grid("s"))
    p.add_argument("--direction", choices=("position-to-sensor", "sensor-to-position"),
                   default="position-to-sensor",
                   help="model the sensor (the document's toolbox, default) or a direct "
                        "compensator")
    p.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    add_parallel_options(p)
    add_read_options(p)
    p.set_defaults(run=_search)
