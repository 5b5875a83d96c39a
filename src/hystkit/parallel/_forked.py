"""The default local executor: Dask's multiprocessing scheduler on forked worker processes.

Imported only when a parallel run starts on a platform that can fork (Linux). Measured on the
2-core machine (load ~5): opening a `distributed` LocalCluster, its first map and closing took
0.6-1.1 s of wall time and importing ``distributed`` 1.1 s more, where a pool of forked
processes took 0.13-0.16 s and ``dask.multiprocessing`` 0.5 s to import: for a ``compare`` whose
parallel map lasts 3-4 s that is the difference between gaining and not. The workers are forked
when the executor opens, with every library the command has imported by then; they keep BLAS on
one thread and make numba ready to load cached kernels at once. ``compare`` opens the
executor before it reads its recordings, so that this start of each worker (~0.2 s) overlaps
work this process does alone (2 workers, 2026-11-24, three runs of 6 alternating pairs: median
0.09-0.12 s less wall time). ``generalize`` gained nothing from simulating its recordings after
the fork (6 pairs, medians equal; the workers then load what the simulation imports
themselves), nor ``select`` from reading after it (4 pairs, -0.04 s): both open it at their
map. Each worker loads the model kernels its pieces use from numba's on-disk cache when it
first runs them, as a serial run does. Loading every family's kernels here before the fork
(`warm_kernels`) cost ~1.05 s of CPU in this process alone, with the other core idle, against
~0.55 s in each worker side by side (``compare`` at 2 workers, 2026-11-24: the same CPU in all,
0.4-0.5 s less wall). A piece's arguments travel with it (pickled by cloudpickle); at 8000
samples the recordings of a piece are 0.2-1.4 MB, under a millisecond to pickle.

Dask's local scheduler runs independent tasks in descending order of their keys
(``dask.order``); the keys here are numbered so that the costliest piece sorts last and runs
first (tested), and the results are put back in the order of the pieces.
"""

from __future__ import annotations

import multiprocessing
import uuid
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import dask
import dask.multiprocessing
from dask.callbacks import Callback
from threadpoolctl import threadpool_limits

from ._contract import _CURRENT, Cost, OnDone, make_numba_ready
from ._cost import cost_order

__all__ = ["ForkedExecutor"]


def _worker_start() -> None:
    """In each worker as it starts: BLAS on one thread (idle OpenBLAS threads spin on the
    other worker's core), no executor current (the parent's was copied by the fork; a fit
    inside a piece stays serial), and numba made ready to load cached kernels (its target
    context, ~0.2 s), which every piece's first kernel call would otherwise do."""
    threadpool_limits(1)  # kept for the worker's life
    _CURRENT.set(None)
    make_numba_ready()


def _run_piece(func: Callable[..., Any], item: Any, shared: Mapping[str, Any]) -> Any:
    return func(item, **shared)


class _Reporter(Callback):
    """Calls ``on_done(index, result)`` in this process as each piece finishes."""

    def __init__(self, index: Mapping[str, int], on_done: OnDone):
        super().__init__()
        self.index, self.on_done = index, on_done

    def _posttask(self, key: str, result: Any, dsk: Any, state: Any, worker_id: Any) -> None:
        if key in self.index:
            self.on_done(self.index[key], result)


class ForkedExecutor:
    """`hystkit.parallel.Executor` on `n_workers` forked processes (Dask's "processes"
    scheduler); close it with `close`."""

    def __init__(self, n_workers: int):
        self.n_workers = n_workers
        self._pool = ProcessPoolExecutor(n_workers, mp_context=multiprocessing.get_context(
            "fork"), initializer=_worker_start)
        self._pool.submit(int)  # fork the workers now, not at the first map: they start
        # while this process does what comes before the map (compare: reading the recordings)

    def describe(self) -> str:
        return f"{self.n_workers} Dask workers (local, forked processes)"

    def map(self, func: Callable[..., Any], items: Sequence[Any], *,
            shared: Mapping[str, Any] | None = None, on_done: OnDone | None = None,
            cost: Cost | None = None) -> list:
        n, run = len(items), uuid.uuid4().hex[:8]
        name = getattr(func, "__name__", "piece")
        keys: list = [None] * n
        for rank, i in enumerate(cost_order(items, cost)):
            keys[i] = f"{name}-{run}-{n - 1 - rank:06d}"  # the costliest sorts last: first
        tasks = [dask.delayed(_run_piece, pure=False)(func, item, dict(shared or {}),
                                                       dask_key_name=keys[i])
                 for i, item in enumerate(items)]
        callbacks = [_Reporter({key: i for i, key in enumerate(keys)}, on_done)._callback] \
            if on_done is not None else []
        # The scheduler as a function, not its name "processes": given a name, dask.compute
        # imports ``distributed`` to look for a client (0.3 s on the idle machine, at the
        # start of every command's first map).
        return list(dask.compute(*tasks, scheduler=dask.multiprocessing.get, pool=self._pool,
                                 num_workers=self.n_workers, chunksize=1,
                                 optimize_graph=False, callbacks=callbacks))

    def close(self) -> None:
        """End the workers; a piece still running (after an error or a signal) is stopped.

        After maps that finished, the workers leave on the pool's own signal. Stopping them
        instead could stop one that waits for work, inside the call queue's lock: the lock
        stays taken and the shutdown waits for ever on the other worker (a ``generalize``
        hung so once, at load ~9)."""
        if getattr(self._pool, "_pending_work_items", None):
            for process in list(getattr(self._pool, "_processes", {}).values()):
                if process.is_alive():
                    process.terminate()
        self._pool.shutdown(wait=True, cancel_futures=True)
