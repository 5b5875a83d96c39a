"""The costliest pieces start first (issue 13), and the cost estimate behind that order."""

from __future__ import annotations

import sys
import time

import cloudpickle
import pytest

from hystkit.models import FAMILIES
from hystkit.parallel import SerialExecutor, fit_cost
from hystkit.parallel._cost import MEASURED
from hystkit.parallel._dask import DaskExecutor, cost_order

cloudpickle.register_pickle_by_value(sys.modules[__name__])


def _started(seconds: float) -> float:
    """When this piece started (clock shared by the worker processes), after a wait."""
    t = time.time()
    time.sleep(seconds)
    return t


def testcost_order_is_costliest_first_and_stable():
    assert cost_order([3, 1, 4, 1, 5], cost=float) == [4, 2, 0, 1, 3]
    assert cost_order("abc", cost=None) == [0, 1, 2]


def test_the_costliest_pieces_start_first_and_results_keep_their_order(parallel_executor):
    costs = [1.0, 4.0, 2.0, 3.0, 0.5]
    items = list(range(5))
    done = []
    runs = parallel_executor.map(_started_item, items, shared={"seconds": 0.4},
                                 cost=lambda i: costs[i], on_done=lambda i, r: done.append(i))
    assert [i for i, _, _ in runs] == items  # results in the order of the pieces
    assert sorted(done) == items  # each reported once
    if not isinstance(parallel_executor, DaskExecutor):  # the forked default
        by_start = sorted(items, key=lambda i: runs[i][1])
        assert set(by_start[:2]) == {1, 3}  # the two costliest first, one on each worker
    else:
        # A Dask scheduler decides which worker runs what, and may move pieces between
        # workers (work stealing): hystkit controls the rank each piece is given.
        by_rank = sorted(items, key=lambda i: runs[i][2])
        assert by_rank == [1, 3, 2, 0, 4]


def _started_item(i: int, *, seconds: float) -> tuple[int, float, tuple | None]:
    """The piece, when it started and, on a Dask worker, the rank the scheduler gave it."""
    rank = None
    try:
        from distributed import get_worker
        from distributed.worker import thread_state

        rank = get_worker().state.tasks[thread_state.key].priority
    except (ImportError, ValueError):  # not on a Dask worker
        pass
    return i, _started(seconds), rank


def test_serial_map_ignores_cost():
    seen = []
    out = SerialExecutor().map(pow, [2, 3], shared={"exp": 2}, cost=lambda x: -x,
                               on_done=lambda i, _: seen.append(i))
    assert out == [4, 9] and seen == [0, 1]


def test_every_family_has_a_measured_cost():
    assert set(MEASURED) == set(FAMILIES)


@pytest.mark.parametrize("name", sorted(MEASURED))
def test_fit_cost_is_linear_in_samples_and_quadratic_in_size(name):
    base = fit_cost(name, 2, 4000)
    assert fit_cost(name, 2, 8000) == pytest.approx(2 * base, rel=1e-12)
    assert fit_cost(name, 4, 4000) == pytest.approx(4 * base, rel=1e-12)
    default = MEASURED[name][1]
    assert fit_cost(name, None, 8000) == fit_cost(name, default, 8000) == MEASURED[name][0]


def test_an_unknown_family_costs_the_median():
    costs = sorted(seconds for seconds, _ in MEASURED.values())
    assert fit_cost("no-such-family", 3, 8000) == costs[len(costs) // 2]
