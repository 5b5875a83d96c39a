"""``hystkit batch SOURCE --out OUT``: fit a fleet of sensors (issue 13.2)."""

from __future__ import annotations

import argparse

from ..batch import jobs_from_folder, pending, read_manifest, run_batch
from ._common import UsageError, failures_exit
from ._many_models import ParallelOptions, open_executor_for
from ._reading import read_options

__all__ = ["run_batch_command"]


def run_batch_command(args: argparse.Namespace) -> int:
    """``hystkit batch``: one model file per sensor and one results table."""
    parallel = ParallelOptions.from_args(args)
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
    n_pieces = len(pending(jobs, args.out, args.force, reading))
    with open_executor_for(parallel, n_pieces) as executor:
        table = run_batch(jobs, args.out, executor=executor, read_options=reading,
                          refit=args.force, source=str(args.source), progress=_say)
    print(f"wrote {args.out / 'results.parquet'}, {args.out / 'results.csv'} and "
          f"{sum(r['status'] != 'failed' for r in table)} model file(s) in "
          f"{args.out / 'models'}")
    return failures_exit([r["sensor"] for r in table if r["status"] != "ok"], "sensor(s)")


def _say(line: str) -> None:
    print(line, flush=True)
