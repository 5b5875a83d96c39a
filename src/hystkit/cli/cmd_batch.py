"""``hystkit batch SOURCE --out OUT``: fit a fleet of sensors (issue 13.2)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import (
    UsageError,
    add_read_options,
    deferred,
    failures_exit,
    positive_int,
    read_options,
)
from .cmd_compare import add_parallel_options, executor_for

__all__ = ["register"]


def _batch(args: argparse.Namespace) -> int:
    from ..batch import jobs_from_folder, pending, read_manifest, run_batch

    defaults = {"model": args.model, "size": args.size, "mode": args.mode,
                "center": args.center}
    if args.source.is_dir():
        jobs = jobs_from_folder(args.source, defaults)
    elif args.source.exists():
        jobs = read_manifest(args.source, defaults)
    else:
        raise UsageError(f"{args.source}: no such manifest or folder")
    print(f"batch of {len(jobs)} sensors from {args.source} into {args.out} (scores on the "
          f"validation recordings: deployable; oracle: each recording's own means, the "
          f"paper's protocol)", flush=True)
    # Every recording as fit reads it: its settings file, then the command line; settled (and
    # said) here, so a settings file that is refused stops the batch before any fit.
    reading = {str(path): read_options(args, path)
               for job in jobs for path in (*job.fit, *job.validate)}
    # a rerun with everything finished starts no cluster
    with executor_for(args, len(pending(jobs, args.out, args.force, reading))) as executor:
        table = run_batch(jobs, args.out, executor=executor, read_options=reading,
                          refit=args.force, source=str(args.source), progress=_say)
    print(f"wrote {args.out / 'results.parquet'}, {args.out / 'results.csv'} and "
          f"{sum(r['status'] != 'failed' for r in table)} model file(s) in "
          f"{args.out / 'models'}")
    return failures_exit([r["sensor"] for r in table if r["status"] != "ok"], "sensor(s)")


def _say(line: str) -> None:
    print(line, flush=True)


def _families() -> list[str]:
    from ..models import FAMILIES

    return sorted(FAMILIES)


def _compensation(name: str):
    from .. import compensation

    return getattr(compensation, name)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``batch``."""
    p = sub.add_parser(
        "batch", help="fit many sensors: one model file each and one results table",
        description="Fit every sensor of a manifest or a folder; OUT gets models/<id>.json, "
                    "sensors/<id>.json and results.parquet/.csv. Rerunning into the same OUT "
                    "skips the sensors already finished (same options and recordings) and "
                    "fits the others; failed sensors are listed and do not stop the batch "
                    "(exit 3 if any sensor failed or a fit failed its guards).")
    p.add_argument("source", type=Path,
                   help="manifest (.csv: columns sensor, fit, validate [, model, size, mode, "
                        "center], several recordings separated by ';'; .toml: [defaults] and "
                        "[[sensor]] tables with id, fit, validate, options) or a folder: each "
                        "sub-folder is a sensor with fit* and val* recordings, each recording "
                        "directly in it a sensor fitted on its first half and validated on "
                        "its second half")
    p.add_argument("--out", type=Path, required=True, help="batch folder (created, or resumed)")
    deferred(p.add_argument("--model", default="mpl"), choices=_families,
             help=lambda: "model family where the manifest names none (default mpl)")
    p.add_argument("--size", type=positive_int, default=None,
                   help="model size where the manifest gives none (default: the family's)")
    deferred(p.add_argument("--mode", default="direct"), choices=lambda: _compensation("MODES"),
             help=lambda: "direct or inverse where the manifest gives none (default direct)")
    deferred(p.add_argument("--center", default=None),
             choices=lambda: _compensation("CENTERS"),
             help=lambda: f"centring where the manifest gives none (default "
                          f"{_compensation('DEFAULT_CENTER')})")
    p.add_argument("--force", action="store_true",
                   help="refit every sensor, also those finished in OUT (and use an OUT that "
                        "is not a batch folder)")
    add_read_options(p)
    add_parallel_options(p)
    p.set_defaults(run=_batch)
