"""What the commands that fit many models share when they run: the families of ``--models``,
the sizes of ``--size MODEL=N``, and the executor of ``--workers`` / ``--scheduler``."""

from __future__ import annotations

import argparse
from collections.abc import Iterable
from dataclasses import dataclass

from ..models import FAMILIES, warm_kernels
from ..parallel import open_executor
from ._common import UsageError, check_size
from ._option_types import positive_int

__all__ = ["ParallelOptions", "models_from", "open_executor_for", "say_where", "sizes_from"]


@dataclass(frozen=True)
class ParallelOptions:
    """Where a command's independent pieces run: ``--workers``, ``--scheduler``,
    ``--scheduler-timeout`` (`hystkit.cli._study_options.add_parallel_options`)."""

    workers: int | None
    scheduler: str | None
    scheduler_timeout: float | None

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> ParallelOptions:
        return cls(args.workers, args.scheduler, args.scheduler_timeout)


def open_executor_for(parallel: ParallelOptions, n_pieces: int):
    """The executor (context manager) of `parallel` for `n_pieces`."""
    if parallel.scheduler_timeout is not None and parallel.scheduler is None:
        raise UsageError("--scheduler-timeout applies to --scheduler only")
    return open_executor(parallel.workers, parallel.scheduler, n_pieces=n_pieces,
                         connect_timeout=parallel.scheduler_timeout, worker_setup=warm_kernels)


def say_where(executor, n_pieces: int) -> None:
    print(f"{n_pieces} pieces of work on {executor.describe()}", flush=True)


def models_from(text: str | None) -> list[str]:
    """The families ``--models`` names (every registered one without it)."""
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


def sizes_from(pairs: Iterable[str]) -> dict[str, int]:
    """``--size MODEL=N`` options; each size checked against its family's limits."""
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
