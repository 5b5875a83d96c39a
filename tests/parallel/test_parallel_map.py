"""The order-keeping map: serial without Dask, on a real Dask cluster, errors and signals."""

from __future__ import annotations

import subprocess
import sys
import time

import cloudpickle
import pytest

from hystkit.errors import HystkitError
from hystkit.parallel import SerialExecutor, open_executor

# the pieces below are defined here: send them to the workers by value
cloudpickle.register_pickle_by_value(sys.modules[__name__])


def _slow_square(x: float, *, delay: float) -> float:
    """x², after a wait that is longest for the first pieces (they finish last)."""
    time.sleep(delay * (3 - x))
    return x * x


def test_serial_map_runs_in_order_and_loads_no_dask():
    code = ("import sys\n"
            "from hystkit.parallel import open_executor\n"
            "seen = []\n"
            "with open_executor(1) as ex:\n"
            "    out = ex.map(pow, [2, 3, 4], shared={'exp': 2},\n"
            "                 on_done=lambda i, r: seen.append(i))\n"
            "assert out == [4, 9, 16] and seen == [0, 1, 2], (out, seen)\n"
            "print(type(ex).__name__, 'distributed' in sys.modules, 'dask' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120).stdout.split()
    assert out == ["SerialExecutor", "False", "False"]


def test_forked_map_runs_in_order_and_does_not_load_distributed():
    """The default local executor never imports ``distributed`` (0.3 s at the idle machine,
    which dask.compute spends looking for a client when the scheduler is given by name)."""
    code = ("import sys\n"
            "from hystkit.parallel import open_executor\n"
            "with open_executor(2) as ex:\n"
            "    out = ex.map(pow, [2, 3, 4, 5], shared={'exp': 2})\n"
            "assert out == [4, 9, 16, 25], out\n"
            "print(type(ex).__name__, 'distributed' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=300).stdout.split()
    assert out == ["ForkedExecutor", "False"]


def test_more_workers_than_pieces_is_serial():
    with open_executor(4, n_pieces=1) as executor:
        assert isinstance(executor, SerialExecutor)


def test_dask_map_keeps_the_order_of_the_pieces(cluster_address):
    """Pieces that finish out of order (the first ones wait longest) come back in the order
    given; which finishes first depends on the machine's load, so only the result is checked."""
    finished = []
    with open_executor(scheduler=cluster_address) as executor:
        assert executor.n_workers == 2
        out = executor.map(_slow_square, [0, 1, 2, 3], shared={"delay": 0.3},
                           on_done=lambda i, r: finished.append((i, r)))
    assert out == [0, 1, 4, 9]
    assert sorted(finished) == [(0, 0), (1, 1), (2, 4), (3, 9)]  # each reported once


def test_a_failing_piece_raises_in_the_caller(parallel_executor):
    with pytest.raises(TypeError):
        parallel_executor.map(pow, [2, "x"], shared={"exp": 2})
    assert parallel_executor.map(pow, [2, 3], shared={"exp": 2}) == [4, 9]  # still usable


def _describe_shared(x: int, *, options: dict, pairs: list) -> tuple:
    return x, type(options).__name__, options, type(pairs).__name__, pairs


def test_shared_containers_arrive_whole_even_empty(parallel_executor):
    """A dict or list passed in `shared` reaches each piece as that dict or list, as it does
    serially (the cluster's scatter would split it into one future per element, and refused
    an empty one)."""
    shared = {"options": {}, "pairs": [(1, 2), (3, 4)]}
    expected = SerialExecutor().map(_describe_shared, [0, 1], shared=shared)
    assert expected == [(0, "dict", {}, "list", [(1, 2), (3, 4)]),
                        (1, "dict", {}, "list", [(1, 2), (3, 4)])]
    assert parallel_executor.map(_describe_shared, [0, 1], shared=shared) == expected


def test_an_unreachable_scheduler_is_one_error(monkeypatch):
    import hystkit.parallel._dask as dask_executor

    monkeypatch.setattr(dask_executor, "CONNECT_TIMEOUT", 1)
    with pytest.raises(HystkitError, match=r"--scheduler tcp://127.0.0.1:9: cannot connect"), \
            open_executor(scheduler="tcp://127.0.0.1:9"):
        pass


def test_closing_after_finished_maps_stops_no_worker(monkeypatch):
    """Workers that wait for work leave on the pool's own signal: stopping one inside the call
    queue's lock would leave the lock taken and the shutdown waiting on the other worker."""
    import multiprocessing.process

    from hystkit.parallel._forked import ForkedExecutor

    stopped = []
    terminate = multiprocessing.process.BaseProcess.terminate
    monkeypatch.setattr(multiprocessing.process.BaseProcess, "terminate",
                        lambda self: (stopped.append(self.pid), terminate(self)))
    executor = ForkedExecutor(2)
    assert executor.map(pow, [2, 3, 4], shared={"exp": 2}) == [4, 9, 16]
    executor.close()
    assert stopped == []
    # a piece still running when the executor closes (an error elsewhere, a signal) is stopped
    executor = ForkedExecutor(2)
    executor._pool.submit(time.sleep, 60)
    executor.close()
    assert stopped
