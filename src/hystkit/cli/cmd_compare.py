"""``hystkit compare`` and ``hystkit generalize``: all model families side by side (issue 4)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import (
    UsageError,
    add_read_options,
    check_size,
    deferred,
    failures_exit,
    number,
    positive_int,
    read_options,
)

__all__ = ["add_parallel_options", "executor_for", "register", "say_where"]


COMPARE_FILES = ["compare.json", "compare.mat"]


def add_parallel_options(p: argparse.ArgumentParser) -> None:
    """``--workers`` and ``--scheduler`` (with ``--scheduler-timeout``): where the command's
    independent pieces run."""
    g = p.add_argument_group("parallel runs (results are the same as a serial run's)")
    x = g.add_mutually_exclusive_group()
    x.add_argument("--workers", type=positive_int, default=None, metavar="N",
                   help="worker processes of a local Dask cluster (default: one per core); "
                        "1: serial, in this process, without Dask")
    x.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on an existing Dask cluster, e.g. tcp://10.0.0.5:8786 (every "
                        "worker needs the same hystkit version)")
    g.add_argument("--scheduler-timeout", type=number(0, 3600, low_open=True), default=None,
                   metavar="SECONDS",
                   help="seconds to reach --scheduler, connection and Dask's handshake "
                        "together (default 20)")


def executor_for(args: argparse.Namespace, n_pieces: int):
    """The executor (context manager) of ``--workers`` / ``--scheduler`` for `n_pieces`."""
    from ..models import warm_kernels
    from ..parallel import open_executor

    if args.scheduler_timeout is not None and args.scheduler is None:
        raise UsageError("--scheduler-timeout applies to --scheduler only")
    return open_executor(args.workers, args.scheduler, n_pieces=n_pieces,
                         connect_timeout=args.scheduler_timeout, worker_setup=warm_kernels)


def say_where(executor, n_pieces: int) -> None:
    print(f"{n_pieces} pieces of work on {executor.describe()}", flush=True)


def _models(text: str | None) -> list[str]:
    from ..models import FAMILIES

    if text is None:
        return sorted(FAMILIES)
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise UsageError(f"--models {text!r} names no model; give one or more of "
                         f"{', '.join(sorted(FAMILIES))}, separated by commas")
    unknown = [n for n in names if n not in FAMILIES]
    if unknown:
        raise UsageError(f"unknown model(s) {', '.join(unknown)}; known: "
                         f"{', '.join(sorted(FAMILIES))}")
    return names


def _sizes(pairs: list[str]) -> dict[str, int]:
    """``--size MODEL=N`` options; each size checked against its family's limits."""
    from ..models import FAMILIES

    out = {}
    for pair in pairs:
        name, _, value = pair.partition("=")
        try:
            if name not in FAMILIES:
                raise argparse.ArgumentTypeError("unknown model")
            out[name] = positive_int(value)
        except argparse.ArgumentTypeError:
            raise UsageError(f"--size expects MODEL=N with a known model and N >= 1, "
                             f"got {pair!r}") from None
        check_size(name, out[name], f"--size {name}=")
    return out


def _compare(args: argparse.Namespace) -> int:
    # Matplotlib and the fits load only for this command.
    from ..compensation import DEFAULT_CENTER
    from ..io import atomic_folder, check_output_folder, read_recording, write_json, write_mat
    from ..studies import compare_models, format_compare

    models = _models(args.models)
    out = args.out
    inputs = [args.data_fit, args.data_val]
    if out is not None:
        check_output_folder(out, COMPARE_FILES, args.force, inputs=inputs)
    sizes = _sizes(args.size)
    if out is not None:
        # compare.mat's writer (scipy.io), loaded before the workers fork: they inherit the
        # scipy core it shares with their fits' scipy.optimize, which each worker and then this
        # process imported on its own (traced at 2 workers, 7 pairs: median 0.11 s less)
        import scipy.io  # noqa: F401
    with executor_for(args, 2 * len(models)) as executor:  # its workers start while we read
        fit_rec = read_recording(args.data_fit, options=read_options(args, args.data_fit))
        val_rec = read_recording(args.data_val, options=read_options(args, args.data_val))
        print(f"comparing {len(models)} models: fit on {args.data_fit}, validate on "
              f"{args.data_val} (deployable centring: {DEFAULT_CENTER}; oracle: recording, "
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
        with atomic_folder(out, args.force, COMPARE_FILES) as tmp:
            write_json(table, tmp / "compare.json")
            write_mat(tmp / "compare.mat", table)  # the same table for MATLAB
        print(f"wrote {out / 'compare.json'}, {out / 'compare.mat'}")
    return failures_exit([name for name, m in table.items() if "error" in m])


def _generalize(args: argparse.Namespace) -> int:
    from ..compensation import DEFAULT_CENTER
    from ..io import atomic_folder, check_output_folder, read_recording, write_json, write_mat
    from ..parallel import loading_meanwhile
    from ..sensors import simulate_experiment
    from ..signals import EXPERIMENTS
    from ..studies import FIGURE_MODULES, generalization_matrix, plot_generalization

    models = _models(args.models)
    out = args.out or Path("hystkit-generalize")
    names = ["generalize.json", "generalize.mat", "generalize.png"]
    check_output_folder(out, names, args.force, inputs=args.data)
    sizes = _sizes(args.size)
    if args.data:
        if len(args.data) < 2:
            raise UsageError("generalize needs at least two recordings (train on each, test on "
                             "every other)")
        recs = {path.stem: read_recording(path, options=read_options(args, path))
                for path in args.data}
        if len(recs) < len(args.data):
            raise UsageError("generalize: recordings need distinct file names (the table uses "
                             "them)")
        train, test, where = recs, recs, "your recordings; the diagonal is the training data"
    else:
        train = {name: simulate_experiment(name, 1) for name in EXPERIMENTS}
        test = {name: simulate_experiment(name, 2) for name in EXPERIMENTS}
        where = "virtual sensor, fit seed 1, test seed 2"
    print(f"train on each of {', '.join(train)}, test on each ({where}; direct-mode "
          f"compensators, deployable centring: {DEFAULT_CENTER}, oracle beside it)")
    with executor_for(args, len(models) * len(train)) as executor:
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
    with atomic_folder(out, args.force, names) as tmp:  # complete or not at all
        write_json(matrix, tmp / "generalize.json")
        write_mat(tmp / "generalize.mat", matrix)
        plot_generalization(matrix).savefig(tmp / "generalize.png", dpi=110)
    print(f"\nwrote {out / 'generalize.json'}, {out / 'generalize.mat'}, "
          f"{out / 'generalize.png'}")
    return failures_exit(failed)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``compare`` and ``generalize``."""
    def models_help() -> str:
        from ..models import FAMILIES

        return f"comma-separated models (default: all: {', '.join(sorted(FAMILIES))})"

    p = sub.add_parser("compare", help="fit every model on one recording, score on another")
    p.add_argument("data_fit", type=Path, help="recording to fit every model on")
    p.add_argument("data_val", type=Path, help="recording to score them on (not seen by the "
                   "fits)")
    deferred(p.add_argument("--models"), help=models_help)
    p.add_argument("--size", action="append", default=[], metavar="MODEL=N",
                   help="model size, e.g. --size mpl=3 (repeatable)")
    p.add_argument("--out", type=Path, help="folder for compare.json and compare.mat (the same "
                   "table for MATLAB)")
    add_read_options(p)
    add_parallel_options(p)
    p.set_defaults(run=_compare)

    p = sub.add_parser("generalize", help="train on each recording, test on each (default: the "
                                          "four virtual-sensor excitations)")
    p.add_argument("data", type=Path, nargs="*",
                   help="your recordings (at least two, one rate); default: the virtual sensor")
    deferred(p.add_argument("--models"), help=models_help)
    p.add_argument("--size", action="append", default=[], metavar="MODEL=N",
                   help="model size, e.g. --size mpl=3 (repeatable; default: each family's own)")
    p.add_argument("--out", type=Path, help="output folder (default hystkit-generalize): "
                   "generalize.json, generalize.mat, generalize.png")
    add_read_options(p)
    add_parallel_options(p)
    p.set_defaults(run=_generalize)
