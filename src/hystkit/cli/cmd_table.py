"""``hystkit table 5.4`` and ``hystkit table 2.2``: the reference document's tables, measured on
the virtual sensor, with the document's numbers beside hystkit's (issue 14.5)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import GUARD_EXIT, UsageError, check_size, integer, number, positive_int

__all__ = ["register"]

_SEED = integer(0, 2**32 - 1)


def _check_out(args: argparse.Namespace, stem: str) -> None:
    """Refuse an existing output before any work (nothing is overwritten without --force)."""
    from ..io import check_output_folder
    from ..studies import output_names

    if args.out is not None:
        check_output_folder(args.out, output_names(stem), args.force)


def _finish(args: argparse.Namespace, stem: str, result: dict, columns) -> None:
    from ..studies import format_markdown, write_table

    print(format_markdown(result["rows"], columns))
    if args.out is not None:
        paths = write_table(args.out, stem, result, result["rows"], force=args.force)
        print(f"wrote {', '.join(str(p) for p in paths)}")


def _table_5_4(args: argparse.Namespace) -> int:
    from ..models import get_family
    from ..studies import TABLE_5_4_COLUMNS, Table54Settings, measure_table_5_4

    family = get_family(args.model)
    if family.invert is None:
        raise UsageError(f"--model {args.model}: table 5.4 compensates with the model's inverse, "
                         f"and {args.model} has none ({family.no_inverse_reason})")
    check_size(args.model, args.size)
    _check_out(args, "table_5_4")
    # the document's mPL has one cell; another family gets its own default size
    size = args.size if args.size is not None else 1 if args.model == "mpl" \
        else family.default_size
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


def _table_2_2(args: argparse.Namespace) -> int:
    from ..studies import TABLE_2_2_COLUMNS, measure_table_2_2
    from .cmd_compare import _models, _sizes

    models = _models(args.models) if args.models else ["pl", "pi", "mpl"]
    sizes = _sizes(args.size)
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


def _excitations() -> list[str]:
    from ..signals import EXPERIMENTS

    return sorted(EXPERIMENTS)


def _common(p: argparse.ArgumentParser, stem: str) -> None:
    p.add_argument("--out", type=Path, help=f"folder for {stem}.json (everything) and "
                   f"{stem}.csv (the table); default: print only")
    # SUPPRESS: a --force given before the table number (hystkit table --force 5.4) stays
    p.add_argument("--force", action="store_true", default=argparse.SUPPRESS,
                   help="overwrite existing output files")


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``table`` with its tables ``5.4`` and ``2.2``."""
    from ._common import deferred

    p = sub.add_parser("table", help="the reference document's tables 5.4 and 2.2 measured on "
                                     "the virtual sensor, the document's numbers beside them")
    tables = p.add_subparsers(dest="table", required=True, metavar="{5.4,2.2}")

    q = tables.add_parser("5.4", help="SINAD and loop area of encoder, R1, R2, R1-R2, fitted "
                                      "model and compensated signal (raw recordings)")
    q.add_argument("--model", default="mpl",
                   help="model family with an inverse (default mpl, as the document)")
    q.add_argument("--size", type=positive_int, default=None,
                   help="model size (default: 1 cell for mpl, as the document; the family's "
                        "default size for another model)")
    q.add_argument("--fit-seed", type=_SEED, default=1, help="seed of the fitting recording")
    q.add_argument("--val-seed", type=_SEED, default=2, help="seed of the validation recording")
    q.add_argument("--scope-rate", type=number(2e3, 2e5), default=20e3, metavar="HZ",
                   help="raw scope rate, at most 2e5 (default 2e4; each 200 s recording takes "
                        "4 kB per Hz of temporary disk: the document's 1.98e6 would need 16 GB)")
    q.add_argument("--quick", action="store_true",
                   help="40 s of each recording at a 10 kHz scope rate, whatever --scope-rate "
                        "says (a few seconds)")
    _common(q, "table_5_4")
    q.set_defaults(run=_table_5_4)

    q = tables.add_parser("2.2", help="min / mean / variance of the RMSE over repeated "
                                      "training and test recordings")
    q.add_argument("--repeats", type=integer(2, 10_000), default=10,
                   help="training/test pairs (default 10)")
    q.add_argument("--seed", type=_SEED, default=1,
                   help="repeat r uses seeds SEED + 2r (training) and SEED + 2r + 1 (test)")
    deferred(q.add_argument("--excitation", default="noise",
                            help="experiment of every recording (default noise: a new "
                                 "trajectory per seed)"), choices=_excitations)
    q.add_argument("--models", help="comma-separated models (default pl,pi,mpl: the "
                                    "document's PL and Kuhnen, and the mPL)")
    q.add_argument("--size", action="append", default=[], metavar="MODEL=N",
                   help="model size, e.g. --size mpl=2 (repeatable)")
    q.add_argument("--quick", action="store_true", help="3 repeats (seconds, for tests)")
    _common(q, "table_2_2")
    q.set_defaults(run=_table_2_2)
