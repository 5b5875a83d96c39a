"""``hystkit table 5.4`` and ``hystkit table 2.2``: the reference document's tables, measured on
the virtual sensor, with the document's numbers beside hystkit's (issue 14.5)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from ..io import check_output_folder
from ..models import get_family
from ..studies import (
    TABLE_2_2_COLUMNS,
    TABLE_5_4_COLUMNS,
    Table54Settings,
    format_markdown,
    measure_table_2_2,
    measure_table_5_4,
    output_names,
    write_table,
)
from ._common import GUARD_EXIT, UsageError, check_size
from ._many_models import models_from, sizes_from

__all__ = ["Table22Options", "Table54Options", "run_table_2_2", "run_table_5_4", "table_2_2",
           "table_5_4"]


@dataclass(frozen=True)
class Table54Options:
    """``hystkit table 5.4``'s options, as parsed: ``size`` None for the family's default;
    ``quick``: 40 s of each recording at a 10 kHz scope rate, whatever ``scope_rate`` says."""

    model: str
    size: int | None
    fit_seed: int
    val_seed: int
    scope_rate: float  # Hz
    quick: bool
    out: Path | None
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> Table54Options:
        """The options of a parsed ``table 5.4`` command line."""
        return cls(args.model, args.size, args.fit_seed, args.val_seed, args.scope_rate,
                   args.quick, args.out, args.force)


@dataclass(frozen=True)
class Table22Options:
    """``hystkit table 2.2``'s options, as parsed (``quick``: 3 repeats, whatever
    ``repeats`` says)."""

    repeats: int
    seed: int
    excitation: str
    models: str | None
    sizes: tuple[str, ...]  # --size MODEL=N, as given
    quick: bool
    out: Path | None
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> Table22Options:
        """The options of a parsed ``table 2.2`` command line."""
        return cls(args.repeats, args.seed, args.excitation, args.models, tuple(args.size),
                   args.quick, args.out, args.force)


def _check_out(opts: Table54Options | Table22Options, stem: str) -> None:
    """Refuse an existing output before any work (nothing is overwritten without --force)."""
    if opts.out is not None:
        check_output_folder(opts.out, output_names(stem), opts.force)


def _finish(opts: Table54Options | Table22Options, stem: str, result: dict, columns) -> None:
    print(format_markdown(result["rows"], columns))
    if opts.out is not None:
        paths = write_table(opts.out, stem, result, result["rows"], force=opts.force)
        print(f"wrote {', '.join(str(p) for p in paths)}")


def run_table_5_4(args: argparse.Namespace) -> int:
    """``hystkit table 5.4``."""
    return table_5_4(Table54Options.from_args(args))


def table_5_4(opts: Table54Options) -> int:
    """Measure table 5.4 on the virtual sensor; print (and write) it."""
    family = get_family(opts.model)
    if family.invert is None:
        raise UsageError(f"--model {opts.model}: table 5.4 compensates with the model's inverse, "
                         f"and {opts.model} has none ({family.no_inverse_reason})")
    check_size(opts.model, opts.size)
    _check_out(opts, "table_5_4")
    # the family's default size (the document's mPL: one cell, mpl's default)
    size = opts.size if opts.size is not None else family.default_size
    print(f"model {opts.model}, size {size}: {family.size_help}"
          f"{'' if opts.size is not None else ' (default)'}")
    settings = Table54Settings(fit_seed=opts.fit_seed, val_seed=opts.val_seed, model=opts.model,
                               size=size, scope_rate=10e3 if opts.quick else opts.scope_rate,
                               duration=40.0 if opts.quick else None)
    result = measure_table_5_4(settings, progress=print)
    fit = result["fit"]
    print(f"\nTable 5.4 on the virtual sensor (raw {settings.excitation} recordings, seeds "
          f"{settings.fit_seed} fit / {settings.val_seed} validation, scope "
          f"{settings.scope_rate:g} Hz); {fit['model']} fitted position -> sensor, inverse as "
          f"compensator: fit {fit['status']} ({fit['status_message']})")
    print("loop area: eq. 5.15 against the encoder position, % per cycle, signed (an output that "
          "lags gives < 0); oracle centring: the validation recording's own means")
    _finish(opts, "table_5_4", result, TABLE_5_4_COLUMNS)
    if result["centring_note"]:
        print(f"note: {result['centring_note']}")
    for note in result["preprocess_warnings"]:
        print(f"hystkit: warning: {note}")
    return 0 if fit["status"] == "ok" else GUARD_EXIT


def run_table_2_2(args: argparse.Namespace) -> int:
    """``hystkit table 2.2``."""
    return table_2_2(Table22Options.from_args(args))


def table_2_2(opts: Table22Options) -> int:
    """Measure table 2.2 on the virtual sensor; print (and write) it."""
    models = models_from(opts.models) if opts.models else ["pl", "pi", "mpl"]
    sizes = sizes_from(opts.sizes)
    _check_out(opts, "table_2_2")
    repeats = 3 if opts.quick else opts.repeats
    print(f"table 2.2: {repeats} repeats, each a fresh {opts.excitation} training and test "
          f"recording of the virtual sensor (seeds {opts.seed} + 2r, + 2r + 1); direct "
          f"compensators of {', '.join(models)} via the generalize matrix")
    result = measure_table_2_2(repeats, opts.seed, excitation=opts.excitation, models=models,
                               sizes=sizes, progress=print)
    print("\nRMSE of the position estimate normalised by the training max |position| "
          "(eq. 5.10-5.11); variance with ddof = 1; the document's PL is pl, its Kuhnen pi")
    _finish(opts, "table_2_2", result, TABLE_2_2_COLUMNS + (("n_flagged", "flagged"),))
    flagged = sorted({row["model"] for row in result["rows"] if row["n_flagged"]})
    for name in flagged:
        print(f"hystkit: warning: {name}: some repeats failed or were disqualified; their "
              f"reasons are in the JSON (repeats -> models -> errors)")
    return GUARD_EXIT if flagged else 0
