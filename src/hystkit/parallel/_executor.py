"""The executor contract, the serial executor, and the choice between it and Dask."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, Protocol

__all__ = ["Executor", "SerialExecutor", "available_cores", "current_executor",
           "open_executor"]

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
        from threadpoolctl import threadpool_limits

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


@contextmanager
def open_executor(workers: int | None = None, scheduler: str | None = None, *,
                  n_pieces: int | None = None,
                  connect_timeout: float | None = None) -> Iterator[Executor]:
    """The executor for one command; its cluster or connection is closed on leaving.

    While it is open, a parallel executor is also `current_executor`, so that a long fit run
    here (such as ``select``'s refit of the winner) screens its starts on the workers.

    Parameters
    ----------
    workers : int, optional
        Worker processes of a local cluster (default: one per available core), forked from
        this process where the platform forks (Dask's multiprocessing scheduler), else a
        ``distributed`` LocalCluster. 1 runs serially in this process, without Dask.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); its workers run the
        pieces and `workers` is ignored.
    n_pieces : int, optional
        How many pieces the command has at most: a local cluster gets no more workers than
        that, and a single piece runs serially.
    connect_timeout : float, optional
        Seconds to reach `scheduler`, its connection and Dask's handshake together (default
        20): a port that accepts the connection but does not answer as a Dask scheduler is
        then refused with a `~hystkit.errors.HystkitError` that says what answered.
    """
    if scheduler is None:
        n = available_cores() if workers is None else workers
        if n_pieces is not None:
            n = min(n, n_pieces)
        if n <= 1:
            yield SerialExecutor()
            return
    with _parallel_executor(n if scheduler is None else None, scheduler,
                            connect_timeout) as executor:
        token = _CURRENT.set(executor)
        try:
            yield executor
        finally:
            _CURRENT.reset(token)


@contextmanager
def _parallel_executor(n_workers: int | None, scheduler: str | None,
                       connect_timeout: float | None = None) -> Iterator[Executor]:
    """Dask's multiprocessing scheduler on forked processes where the platform forks (the
    fastest to start, `._forked`); elsewhere a `distributed` LocalCluster of spawned workers,
    and for a scheduler address a client of it (`._dask`). Dask loads only here."""
    if scheduler is None and can_fork():
        from ._forked import ForkedExecutor

        executor = ForkedExecutor(n_workers)
        try:
            yield executor
        finally:
            executor.close()
        return
    from ._dask import dask_executor

    with dask_executor(n_workers, scheduler, connect_timeout) as executor:
        yield executor


def can_fork() -> bool:
    """Whether worker processes can be forked from this one (Linux)."""
    import multiprocessing  # only for a parallel run

    return sys.platform.startswith("linux") and \
        "fork" in multiprocessing.get_all_start_methods()
