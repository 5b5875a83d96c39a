"""``hystkit batch SOURCE --out OUT``: fit a fleet of sensors (issue 13.2)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from ..batch import jobs_from_folder, pending, read_manifest, run_batch
from ._common import UsageError, failures_exit
from ._many_models import ParallelOptions, open_executor_for
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["BatchOptions", "run_batch_command"]


@dataclass(frozen=True)
class BatchOptions:
    """``hystkit batch``'s options, as parsed: `defaults` are the fit's where the manifest
    gives none (``model``, ``size``, ``mode``, ``center``)."""

    source: Path
    out: Path
    defaults: dict[str, object]
    force: bool
    parallel: ParallelOptions
    reader: Reader  # the recordings' reading options

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> BatchOptions:
        """The options of a parsed ``batch`` command line."""
        defaults = {"model": args.model, "size": args.size, "mode": args.mode,
                    "center": args.center}
        return cls(args.source, args.out, defaults, args.force, ParallelOptions.from_args(args),
                   Reader(given_read_options(args)))


def run_batch_command(args: argparse.Namespace) -> int:
    """``hystkit batch``: one model file per sensor and one results table."""
    return batch(BatchOptions.from_args(args))


def batch(opts: BatchOptions) -> int:
    """Fit every sensor of the manifest or folder not finished yet; write the table."""
    if opts.source.is_dir():
        jobs = jobs_from_folder(opts.source, opts.defaults)
    elif opts.source.exists():
        jobs = read_manifest(opts.source, opts.defaults)
    else:
        raise UsageError(f"{opts.source}: no such manifest or folder")
    print(f"batch of {len(jobs)} sensors from {opts.source} into {opts.out} (scores on the "
          f"validation recordings: deployable; oracle: each recording's own means, the "
          f"paper's protocol)", flush=True)
    # Every recording as fit reads it: its settings file, then the command line; settled (and
    # said) here, so a settings file that is refused stops the batch before any fit.
    reading = {str(path): opts.reader.options(path)
               for job in jobs for path in (*job.fit, *job.validate)}
    # a rerun with everything finished starts no cluster
    n_pieces = len(pending(jobs, opts.out, opts.force, reading))
    with open_executor_for(opts.parallel, n_pieces) as executor:
        table = run_batch(jobs, opts.out, executor=executor, read_options=reading,
                          refit=opts.force, source=str(opts.source), progress=_say)
    print(f"wrote {opts.out / 'results.parquet'}, {opts.out / 'results.csv'} and "
          f"{sum(r['status'] != 'failed' for r in table)} model file(s) in "
          f"{opts.out / 'models'}")
    return failures_exit([r["sensor"] for r in table if r["status"] != "ok"], "sensor(s)")


def _say(line: str) -> None:
    print(line, flush=True)
