"""The ``distributed`` executor: a client of a running scheduler (``--scheduler``), or a local
cluster where the platform cannot fork (elsewhere `._forked` starts faster).

Imported only when such a run starts. A local cluster's workers are forked where possible:
they inherit the libraries this process has imported and the model kernels it loaded from
numba's on-disk cache (the command's ``worker_setup``, run once before the fork), so a worker
is ready in a fraction of a second, where a spawned one re-imports numpy, scipy, numba and
hystkit (2-3 s on a loaded 2-core machine). Spawned workers and those of a remote cluster run
the set-up at their start (`WorkerSetup`); forked ones skip it (measured: it cost each of two forked
workers 0.6-2.6 s of CPU at every start, for kernels they already had). Every worker limits its
BLAS to one thread: a worker has one core, and idle OpenBLAS threads spin, taking CPU from the
other workers (measured: ``select`` at 2 workers used 40 % more CPU than serially without it).
Pieces go to the scheduler as one graph, listed costliest first (Dask ranks a map's pieces
in the order listed).
"""

from __future__ import annotations

import logging
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import ExitStack, contextmanager
from typing import Any

import dask
from distributed import Client, LocalCluster, WorkerPlugin, as_completed
from threadpoolctl import threadpool_limits

from .. import __version__
from ._contract import Cost, OnDone, can_fork
from ._cost import cost_order
from ._reach import DEFAULT_CONNECT_TIMEOUT, SchedulerError, check_handshake

__all__ = ["DaskExecutor", "SchedulerError", "WorkerSetup", "dask_executor"]

# Seconds to reach a scheduler (connection and handshake), unless the caller gives its own, and
# to close a client or cluster (a cluster whose workers a signal has just ended must not hold
# the command's exit).
CONNECT_TIMEOUT = DEFAULT_CONNECT_TIMEOUT
CLOSE_TIMEOUT = 3
# No dashboard; the scheduler's HTTP server (health checks) on a free port, not 8787, which
# another cluster may hold (then Dask warns and moves).
NO_DASHBOARD = {"dashboard_address": None, "scheduler_kwargs": {"dashboard_address": ":0"}}


# The worker set-ups this process has run: a worker forked from it has them too.
_RUN_HERE: set[str] = set()


def run_setup(setup: Callable[[], None]) -> None:
    """`setup` unless this process (or the one it was forked from) has run it."""
    key = f"{setup.__module__}.{setup.__qualname__}"
    if key not in _RUN_HERE:
        setup()
        _RUN_HERE.add(key)


class WorkerSetup(WorkerPlugin):
    """Worker start-up: BLAS on one thread, and the command's `setup` (`open_executor`'s
    ``worker_setup``) unless the worker was forked from a process that ran it."""

    name = "hystkit-worker-setup"

    def __init__(self, setup: Callable[[], None] | None = None):
        self.setup_once = setup

    def setup(self, worker: Any) -> None:
        threadpool_limits(1)  # kept for the worker's life (not used as a context manager)
        if self.setup_once is not None:
            run_setup(self.setup_once)


def _worker_version() -> str:
    return __version__


class DaskExecutor:
    """`hystkit.parallel.Executor` on a Dask client."""

    def __init__(self, client: Client, where: str):
        self.client = client
        self.where = where

    @property
    def n_workers(self) -> int:
        return max(1, len(self.client.scheduler_info()["workers"]))

    def describe(self) -> str:
        return f"{self.n_workers} Dask workers ({self.where})"

    def map(self, func: Callable[..., Any], items: Sequence[Any], *,
            shared: Mapping[str, Any] | None = None, on_done: OnDone | None = None,
            cost: Cost | None = None) -> list:
        # Shared inputs (recordings) travel to each worker once, not with every piece; each
        # as one object (scatter splits a list or dict into one future per element, and
        # refuses an empty one)
        sent = {key: value if value is None else self.client.scatter([value], broadcast=True,
                                                                     hash=False)[0]
                for key, value in (shared or {}).items()}
        run = uuid.uuid4().hex[:8]
        name = getattr(func, "__name__", "piece")
        # One graph, its pieces listed costliest first: Dask's map ranks them in that order
        # (internal priority), and the scheduler sees them all before it hands one out (a
        # submit per piece let it place the first ones before it knew the costlier ones).
        order = cost_order(items, cost)
        placed = self.client.map(func, [items[i] for i in order], **sent, pure=False,
                                 key=[f"{name}-{run}-{i}" for i in order])
        futures: list = [None] * len(items)
        for i, future in zip(order, placed):
            futures[i] = future
        index = {future.key: i for i, future in enumerate(futures)}
        results: list = [None] * len(futures)
        try:
            for future in as_completed(futures):
                i = index[future.key]
                results[i] = future.result()
                if on_done is not None:
                    on_done(i, results[i])
        finally:  # an error or a signal: nothing left running for this map
            self.client.cancel(futures)
        return results


def _fork_if_possible() -> str:
    return "fork" if can_fork() else "spawn"


@contextmanager
def dask_executor(n_workers: int | None, scheduler: str | None,
                  connect_timeout: float | None = None,
                  worker_setup: Callable[[], None] | None = None) -> Iterator[DaskExecutor]:
    """A local cluster of `n_workers` processes (one thread each), or a client of `scheduler`
    reached within `connect_timeout` seconds (default `CONNECT_TIMEOUT`); both closed on
    leaving, also on Ctrl-C and SIGTERM. Every worker runs `worker_setup` at its start (a
    forked one inherits it from this process, which runs it once before the fork)."""
    with ExitStack() as stack:
        if scheduler is None:
            method = _fork_if_possible()
            if method == "fork" and worker_setup is not None:
                run_setup(worker_setup)
            # for the cluster's whole life: a worker the nanny restarts is forked too (a
            # spawned one would also leave semaphores for multiprocessing's tracker to warn of)
            stack.enter_context(dask.config.set({"distributed.worker.multiprocessing-method":
                                                 method}))
            cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                   silence_logs=logging.CRITICAL, **NO_DASHBOARD)
            stack.callback(cluster.close, timeout=CLOSE_TIMEOUT)
            client = Client(cluster)
            where = f"local, {method}ed"
        else:
            client = _connect(scheduler, CONNECT_TIMEOUT if connect_timeout is None
                              else connect_timeout)
            where = scheduler
        stack.callback(client.close, timeout=CLOSE_TIMEOUT)
        _check_workers(client, where, worker_setup)
        yield DaskExecutor(client, where)


def _connect(address: str, timeout: float) -> Client:
    # Dask's Client bounds the connection but not the server's handshake: a port that accepts
    # and never answers held it for ever. Its handshake is first completed here, bounded.
    check_handshake(address, timeout)
    try:
        return Client(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerError(f"--scheduler {address}: cannot connect to a Dask scheduler "
                             f"there ({type(exc).__name__}: {exc})") from None


def _check_workers(client: Client, where: str,
                   worker_setup: Callable[[], None] | None) -> None:
    """Same hystkit on every worker (a different version could give different numbers), then
    `WorkerSetup` on each and on every worker that joins later."""
    try:
        versions = client.run(_worker_version)
    except (ImportError, ModuleNotFoundError) as exc:
        raise SchedulerError(f"the Dask workers ({where}) cannot import hystkit: install "
                             f"hystkit {__version__} there ({exc})") from None
    if not versions:
        raise SchedulerError(f"the Dask scheduler ({where}) has no workers")
    other = sorted({v for v in versions.values() if v != __version__})
    if other:
        raise SchedulerError(f"the Dask workers ({where}) run hystkit {', '.join(other)}, "
                             f"this is {__version__}: install the same version on both")
    client.register_plugin(WorkerSetup(worker_setup))
