"""``hystkit compare`` and ``hystkit generalize``: all model families side by side (issue 4)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from ..compensation import DEFAULT_CENTER
from ..io import atomic_folder, check_output_folder, read_recording, write_json, write_mat
from ..parallel import loading_meanwhile
from ..sensors import simulate_experiment
from ..signals import EXPERIMENTS
from ..studies import (
    FIGURE_MODULES,
    compare_models,
    format_compare,
    generalization_matrix,
    plot_generalization,
)
from ._common import UsageError, failures_exit
from ._many_models import ParallelOptions, models_from, open_executor_for, say_where, sizes_from
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["CompareOptions", "run_compare", "run_generalize"]


COMPARE_FILES = ["compare.json", "compare.mat"]


@dataclass(frozen=True)
class CompareOptions:
    """``hystkit compare``'s and ``hystkit generalize``'s options, as parsed: ``compare``
    fits on ``data[0]`` and scores on ``data[1]``; ``generalize`` trains and tests on each of
    ``data`` (none: the virtual sensor's experiments)."""

    data: tuple[Path, ...]
    models: str | None
    sizes: tuple[str, ...]  # --size MODEL=N, as given
    out: Path | None
    force: bool
    parallel: ParallelOptions
    reader: Reader  # the recordings' reading options

    @classmethod
    def from_args(cls, args: argparse.Namespace, data: list[Path]) -> CompareOptions:
        """The options of a parsed ``compare`` or ``generalize`` command line."""
        return cls(tuple(data), args.models, tuple(args.size), args.out, args.force,
                   ParallelOptions.from_args(args), Reader(given_read_options(args)))


def run_compare(args: argparse.Namespace) -> int:
    """``hystkit compare``: every family fitted on one recording, scored on another."""
    return compare(CompareOptions.from_args(args, [args.data_fit, args.data_val]))


def compare(opts: CompareOptions) -> int:
    """Every family of ``opts.models`` fitted on one recording and scored on the other."""
    models = models_from(opts.models)
    out = opts.out
    data_fit, data_val = opts.data
    if out is not None:
        check_output_folder(out, COMPARE_FILES, opts.force, inputs=opts.data)
    sizes = sizes_from(opts.sizes)
    if out is not None:
        # compare.mat's writer (scipy.io), loaded before the workers fork: they inherit the
        # scipy core it shares with their fits' scipy.optimize, which each worker and then this
        # process imported on its own (traced at 2 workers, 7 pairs: median 0.11 s less)
        import scipy.io  # noqa: F401
    # its workers start while we read
    with open_executor_for(opts.parallel, 2 * len(models)) as executor:
        fit_rec = read_recording(data_fit, options=opts.reader.options(data_fit))
        val_rec = read_recording(data_val, options=opts.reader.options(data_val))
        print(f"comparing {len(models)} models: fit on {data_fit}, validate on "
              f"{data_val} (deployable centring: {DEFAULT_CENTER}; oracle: recording, "
              "the paper's protocol)")
        say_where(executor, 2 * len(models))
        table = compare_models(fit_rec, val_rec, models, sizes, progress=print,
                               executor=executor)
    print(format_compare(table))
    print("R² fwd: forward model position -> sensor; R² inv: its inverse as compensator; "
          "R² dir: a compensator fitted sensor -> position; line: straight line; left of | "
          "with the fitting recording's offsets (deployable), right of it with the validation "
          "recording's own means (oracle)")
    if out is not None:
        with atomic_folder(out, opts.force, COMPARE_FILES) as tmp:
            write_json(table, tmp / "compare.json")
            write_mat(tmp / "compare.mat", table)  # the same table for MATLAB
        print(f"wrote {out / 'compare.json'}, {out / 'compare.mat'}")
    return failures_exit([name for name, m in table.items() if "error" in m])


def run_generalize(args: argparse.Namespace) -> int:
    """``hystkit generalize``: train on each recording, test on each."""
    return generalize(CompareOptions.from_args(args, args.data))


def generalize(opts: CompareOptions) -> int:
    """The generalisation matrix of every family of ``opts.models``, printed and written."""
    models = models_from(opts.models)
    out = opts.out or Path("hystkit-generalize")
    names = ["generalize.json", "generalize.mat", "generalize.png"]
    check_output_folder(out, names, opts.force, inputs=opts.data)
    sizes = sizes_from(opts.sizes)
    if opts.data:
        if len(opts.data) < 2:
            raise UsageError("generalize needs at least two recordings (train on each, test on "
                             "every other)")
        recs = {path.stem: read_recording(path, options=opts.reader.options(path))
                for path in opts.data}
        if len(recs) < len(opts.data):
            raise UsageError("generalize: recordings need distinct file names (the table uses "
                             "them)")
        train, test, where = recs, recs, "your recordings; the diagonal is the training data"
    else:
        train = {name: simulate_experiment(name, 1) for name in EXPERIMENTS}
        test = {name: simulate_experiment(name, 2) for name in EXPERIMENTS}
        where = "virtual sensor, fit seed 1, test seed 2"
    print(f"train on each of {', '.join(train)}, test on each ({where}; direct-mode "
          f"compensators, deployable centring: {DEFAULT_CENTER}, oracle beside it)")
    with open_executor_for(opts.parallel, len(models) * len(train)) as executor:
        say_where(executor, len(models) * len(train))
        # the figure's matplotlib (~0.3 s) and generalize.mat's writer (scipy.io, ~0.13 s)
        # load while the workers run the map
        with loading_meanwhile(executor, (*FIGURE_MODULES, "scipy.io")):
            matrix = generalization_matrix(train, test, models, sizes, progress=print,
                                           executor=executor)
    failed = []
    for name, entry in matrix.items():
        for key, label in (("r2", "deployable R²"), ("r2_oracle", "oracle R² (recording)")):
            print(f"\n{name}: {label} (rows: trained on, columns: tested on)")
            print(f"{'':<12}" + "".join(f"{t[:11]:>12}" for t in test))
            for train_name, row in entry[key].items():
                print(f"{train_name[:11]:<12}" + "".join(
                    f"{'fail' if v is None else f'{v:.4f}':>12}" for v in row.values()))
        for where_, reason in entry["errors"].items():
            print(f"  {name} {where_}: FAILED: {reason}")
        for where_, reason in entry["notes"].items():
            print(f"  {name} {where_}: note: {reason}")
        if entry["errors"]:
            failed.append(name)
    with atomic_folder(out, opts.force, names) as tmp:  # complete or not at all
        write_json(matrix, tmp / "generalize.json")
        write_mat(tmp / "generalize.mat", matrix)
        plot_generalization(matrix).savefig(tmp / "generalize.png", dpi=110)
    print(f"\nwrote {out / 'generalize.json'}, {out / 'generalize.mat'}, "
          f"{out / 'generalize.png'}")
    return failures_exit(failed)
