"""The executor contract, the serial executor, the executor open in this thread, and what
every worker process does before its first piece (`make_numba_ready`)."""

from __future__ import annotations

import multiprocessing
import os
import sys
from collections.abc import Callable, Mapping, Sequence
from contextvars import ContextVar
from typing import Any, Protocol

from threadpoolctl import threadpool_limits

__all__ = ["Cost", "Executor", "OnDone", "SerialExecutor", "available_cores", "can_fork",
           "current_executor", "make_numba_ready"]

OnDone = Callable[[int, Any], None]
Cost = Callable[[Any], float]

# The parallel executor open in this thread of this process, for work that splits itself
# (the starts of a fit's multi-start). A Dask worker's task threads never see it: a piece
# running there stays serial inside.
_CURRENT: ContextVar[Executor | None] = ContextVar("hystkit_executor", default=None)


class Executor(Protocol):
    """Runs ``func(item, **shared)`` for every item; results in the order of `items`.

    Parameters
    ----------
    *args, **kwargs
        None: this protocol describes executors (`SerialExecutor`, the Dask ones) and is not
        instantiated itself.
    """

    n_workers: int

    def map(self, func: Callable[..., Any], items: Sequence[Any], *,
            shared: Mapping[str, Any] | None = None, on_done: OnDone | None = None,
            cost: Cost | None = None) -> list:
        """``[func(item, **shared) for item in items]``; `on_done(index, result)` is called as
        each piece finishes (in finishing order). `cost(item)` is an estimate of a piece's
        work: the costliest start first, so that no long piece is left to run alone at the
        end (the results keep the order of `items`). An exception of a piece is raised here."""
        ...

    def describe(self) -> str:
        """Where the pieces run, for a progress line."""
        ...


class SerialExecutor:
    """Every piece in this process, one after the other (``--workers 1``), with BLAS on one
    thread like a Dask worker: the fits' tall, narrow Jacobians gain nothing from more, and
    idle OpenBLAS threads spin (``select`` on a busy 2-core machine: 47 s with two BLAS
    threads, 19 s with one).
    """

    n_workers = 1

    def map(self, func: Callable[..., Any], items: Sequence[Any], *,
            shared: Mapping[str, Any] | None = None, on_done: OnDone | None = None,
            cost: Cost | None = None) -> list:
        results = []  # in the given order: `cost` changes nothing for one worker
        with threadpool_limits(1):
            for i, item in enumerate(items):
                results.append(func(item, **(shared or {})))
                if on_done is not None:
                    on_done(i, results[-1])
        return results

    def describe(self) -> str:
        return "this process, one after the other"


def available_cores() -> int:
    """Cores this process may run on (its affinity mask, not the machine's count).

    Returns
    -------
    int
        The number of cores in the affinity mask; off Linux, ``os.cpu_count()`` (1 if unknown).
    """
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def current_executor() -> Executor | None:
    """The parallel executor that `open_executor` holds open here, if any.

    Work that can split itself, such as a fit's starts, asks this.

    Returns
    -------
    Executor or None
        The open parallel executor of this thread; None when the run is serial or this is
        a Dask worker.
    """
    return _CURRENT.get()


def can_fork() -> bool:
    """Whether worker processes can be forked from this one (Linux)."""
    return sys.platform.startswith("linux") and \
        "fork" in multiprocessing.get_all_start_methods()


def make_numba_ready() -> None:
    """Make numba ready to load cached kernels: its target context (every implementation
    registry, scipy.linalg for LAPACK; ~0.2 s), which the first kernel call of a process would
    otherwise set up. Under numba's compiler lock, so never beside a kernel load in another
    thread."""
    # numba (~0.2 s) only here: hystkit.parallel itself loads no compiled code
    from numba.core.compiler_lock import global_compiler_lock
    from numba.core.registry import cpu_target

    with global_compiler_lock:
        cpu_target.target_context.refresh()
