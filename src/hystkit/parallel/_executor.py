"""The choice of executor for one command: serial in this process, forked workers, or Dask."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager

from ._contract import _CURRENT, Executor, SerialExecutor, available_cores, can_fork

__all__ = ["open_executor"]


@contextmanager
def open_executor(workers: int | None = None, scheduler: str | None = None, *,
                  n_pieces: int | None = None, connect_timeout: float | None = None,
                  worker_setup: Callable[[], None] | None = None) -> Iterator[Executor]:
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
    worker_setup : callable, optional
        Run once in every Dask worker process before its first piece (a module-level function:
        it travels to remote workers by name), e.g. loading the kernels the pieces will use;
        a local cluster forked from this process runs it here once, before the fork. Forked
        workers (the default on Linux) do not run it: each loads what its pieces use.
    """
    if scheduler is None:
        n = available_cores() if workers is None else workers
        if n_pieces is not None:
            n = min(n, n_pieces)
        if n <= 1:
            yield SerialExecutor()
            return
    with _parallel_executor(n if scheduler is None else None, scheduler, connect_timeout,
                            worker_setup) as executor:
        token = _CURRENT.set(executor)
        try:
            yield executor
        finally:
            _CURRENT.reset(token)


@contextmanager
def _parallel_executor(n_workers: int | None, scheduler: str | None,
                       connect_timeout: float | None,
                       worker_setup: Callable[[], None] | None) -> Iterator[Executor]:
    """Dask's multiprocessing scheduler on forked processes where the platform forks (the
    fastest to start, `._forked`); elsewhere a `distributed` LocalCluster of spawned workers,
    and for a scheduler address a client of it (`._dask`). Dask loads only here."""
    if scheduler is None and can_fork():
        # Dask (~0.5 s) only for a parallel run: a serial one never imports it
        from ._forked import ForkedExecutor

        executor = ForkedExecutor(n_workers)
        try:
            yield executor
        finally:
            executor.close()
        return
    from ._dask import dask_executor

    with dask_executor(n_workers, scheduler, connect_timeout, worker_setup) as executor:
        yield executor
