"""``hystkit pl-search DATA_FIT``: exhaustive N, p, M, S search of the Power-Law model (table 5.1)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from ..compensation import check_fitting_data
from ..io import check_output_path, write_json
from ..models.pl import FAMILY, PlStructure, format_search_table, structural_search
from ._many_models import ParallelOptions, open_executor_for, say_where
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["PlSearchOptions", "pl_search", "run_pl_search"]


@dataclass(frozen=True)
class PlSearchOptions:
    """``hystkit pl-search``'s options, as parsed: the values of N, p, M and S searched
    (``n``, ``p``, ``m``, ``s``; each given or the model's default grid)."""

    data: Path
    n: tuple[int, ...]
    p: tuple[float, ...]
    m: tuple[int, ...]
    s: tuple[float, ...]
    direction: str  # "position-to-sensor" or "sensor-to-position"
    json: Path | None
    force: bool
    parallel: ParallelOptions
    reader: Reader  # how `data` is read

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> PlSearchOptions:
        """The options of a parsed ``pl-search`` command line."""
        return cls(args.data, args.n, args.p, args.m, args.s, args.direction, args.json,
                   args.force, ParallelOptions.from_args(args),
                   Reader(given_read_options(args)))

    @property
    def grid(self) -> dict[str, tuple]:
        """The searched values by `hystkit.models.pl.structural_search`'s keys."""
        return {"n": self.n, "p": self.p, "m": self.m, "s": self.s}


def run_pl_search(args: argparse.Namespace) -> int:
    """``hystkit pl-search``: the Power-Law model's structural search on one recording."""
    return pl_search(PlSearchOptions.from_args(args))


def pl_search(opts: PlSearchOptions) -> int:
    """Search every N, p, M, S of ``opts.grid`` on ``opts.data``; print (and write) the rows."""
    if opts.json is not None:
        check_output_path(opts.json, opts.force, inputs=[opts.data])
    rec = opts.reader.recording(opts.data)
    # What `fit` demands (samples per parameter, a position and sensor that move), for the
    # largest structure of the grid: two samples "fit" every structure with e_rms 0.000 %.
    check_fitting_data([rec], FAMILY, PlStructure(n_cells=max(opts.n), n_basis=max(opts.m),
                                                  dt=rec.dt))
    u, y = ((rec.position, rec.sensor) if opts.direction == "position-to-sensor"
            else (rec.sensor, rec.position))
    grid = opts.grid
    n_pieces = len(opts.n) * len(opts.p) * len(opts.m) * len(opts.s)
    with open_executor_for(opts.parallel, n_pieces) as executor:
        say_where(executor, n_pieces)
        rows = structural_search(u, y, rec.dt, grid, executor=executor)
    print(f"{opts.data}: Power-Law structural search, {opts.direction}, {u.size} samples, "
          f"dt = {rec.dt:g} s (errors eq. 5.11 on data normalised by eq. 5.10)")
    print(format_search_table(rows))
    best = min(rows, key=lambda r: r["e_rms_pct"])
    print(f"best: N = {best['n_cells']}, p = {best['power']:g}, M = {best['n_basis']}, "
          f"S = {best['smoothing']:g} (e_rms {best['e_rms_pct']:.3f} %)")
    if opts.json is not None:
        write_json({"data": str(opts.data), "direction": opts.direction, "grid": grid,
                    "rows": rows}, opts.json, force=opts.force)
        print(f"wrote {opts.json}")
    return 0
