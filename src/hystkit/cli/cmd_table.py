"""``hystkit table 5.4`` and ``hystkit table 2.2``: the reference document's tables, measured on
the virtual sensor, with the document's numbers beside hystkit's (issue 14.5)."""

from __future__ import annotations

import argparse

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

__all__ = ["run_table_2_2", "run_table_5_4"]


def _check_out(args: argparse.Namespace, stem: str) -> None:
    """Refuse an existing output before any work (nothing is overwritten without --force)."""
    if args.out is not None:
        check_output_folder(args.out, output_names(stem), args.force)


def _finish(args: argparse.Namespace, stem: str, result: dict, columns) -> None:
    print(format_markdown(result["rows"], columns))
    if args.out is not None:
        paths = write_table(args.out, stem, result, result["rows"], force=args.force)
        print(f"wrote {', '.join(str(p) for p in paths)}")


def run_table_5_4(args: argparse.Namespace) -> int:
    """``hystkit table 5.4``."""
    family = get_family(args.model)
    if family.invert is None:
        raise UsageError(f"--model {args.model}: table 5.4 compensates with the model's inverse, "
                         f"and {args.model} has none ({family.no_inverse_reason})")
    check_size(args.model, args.size)
    _check_out(args, "table_5_4")
    # the family's default size (the document's mPL: one cell, mpl's default)
    size = args.size if args.size is not None else family.default_size
    print(f"model {args.model}, size {size}: {family.size_help}"
          f"{'' if args.size is not None else ' (default)'}")
    settings = Table54Settings(fit_seed=args.fit_seed, val_seed=args.val_seed, model=args.model,
                               size=size, scope_rate=10e3 if args.quick else args.scope_rate,
                               duration=40.0 if args.quick else None)
    result = measure_table_5_4(settings, progress=print)
    fit = result["fit"]
    print(f"\nTable 5.4 on the virtual sensor (raw {settings.excitation} recordings, seeds "
          f"{settings.fit_seed} fit / {settings.val_seed} validation, scope "
          f"{settings.scope_rate:g} Hz); {fit['model']} fitted position -> sensor, inverse as "
          f"compensator: fit {fit['status']} ({fit['status_message']})")
    print("loop area: eq. 5.15 against the encoder position, % per cycle, signed (an output that "
          "lags gives < 0); oracle centring: the validation recording's own means")
    _finish(args, "table_5_4", result, TABLE_5_4_COLUMNS)
    if result["centring_note"]:
        print(f"note: {result['centring_note']}")
    for note in result["preprocess_warnings"]:
        print(f"hystkit: warning: {note}")
    return 0 if fit["status"] == "ok" else GUARD_EXIT


def run_table_2_2(args: argparse.Namespace) -> int:
    """``hystkit table 2.2``."""
    models = models_from(args.models) if args.models else ["pl", "pi", "mpl"]
    sizes = sizes_from(args.size)
    _check_out(args, "table_2_2")
    repeats = 3 if args.quick else args.repeats
    print(f"table 2.2: {repeats} repeats, each a fresh {args.excitation} training and test "
          f"recording of the virtual sensor (seeds {args.seed} + 2r, + 2r + 1); direct "
          f"compensators of {', '.join(models)} via the generalize matrix")
    result = measure_table_2_2(repeats, args.seed, excitation=args.excitation, models=models,
                               sizes=sizes, progress=print)
    print("\nRMSE of the position estimate normalised by the training max |position| "
          "(eq. 5.10-5.11); variance with ddof = 1; the document's PL is pl, its Kuhnen pi")
    _finish(args, "table_2_2", result, TABLE_2_2_COLUMNS + (("n_flagged", "flagged"),))
    flagged = sorted({row["model"] for row in result["rows"] if row["n_flagged"]})
    for name in flagged:
        print(f"hystkit: warning: {name}: some repeats failed or were disqualified; their "
              f"reasons are in the JSON (repeats -> models -> errors)")
    return GUARD_EXIT if flagged else 0
