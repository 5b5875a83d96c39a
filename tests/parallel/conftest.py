"""The parallel tests' executors: one real Dask cluster of two spawned worker processes, as a
cluster started outside hystkit would have (hystkit reaches it with ``--scheduler``), and
hystkit's default local executor, two worker processes forked from the test process."""

from __future__ import annotations

import logging

import pytest

from hystkit.io import Recording
from hystkit.sensors import simulate_experiment

# The cluster opens at the first test that asks for it and closes when this worker's next test
# is outside tests/parallel, not at the session's end: idle, its scheduler and two workers took
# ~0.07 s of CPU a second (2026-11-29), ~14 s over the ~200 s of other files a worker then ran.
# (A package-scoped fixture would need tests/parallel/__init__.py, which renames the test
# modules to ``parallel.*``; the cluster's workers then fail to import the pieces they run.)
_CLUSTER: dict = {}


@pytest.fixture
def cluster_address() -> str:
    if "cluster" not in _CLUSTER:
        distributed = pytest.importorskip("distributed")
        from hystkit.parallel._dask import NO_DASHBOARD

        _CLUSTER["cluster"] = distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, silence_logs=logging.CRITICAL,
            **NO_DASHBOARD)
    return _CLUSTER["cluster"].scheduler_address


@pytest.hookimpl(trylast=True)  # after the test's own fixtures (a client of the cluster) end
def pytest_runtest_teardown(item, nextitem):
    if nextitem is None or nextitem.path.parent != item.path.parent:
        cluster = _CLUSTER.pop("cluster", None)
        if cluster is not None:
            cluster.close()


@pytest.fixture(scope="session")
def forked():
    """What `open_executor(2)` opens on Linux: Dask's multiprocessing scheduler on two forked
    workers, kept open (but not made current: see `current`)."""
    pytest.importorskip("dask")
    from hystkit.parallel._forked import ForkedExecutor

    executor = ForkedExecutor(2)
    yield executor
    executor.close()


@pytest.fixture(params=["forked", "cluster"])
def parallel_executor(request, cluster_address):
    """Each parallel executor in turn: the forked default and a client of the cluster."""
    from hystkit.parallel import open_executor

    if request.param == "forked":
        yield request.getfixturevalue("forked")
        return
    with open_executor(scheduler=cluster_address) as executor:
        yield executor


@pytest.fixture
def current():
    """Makes an executor current for one test, as `open_executor` does while it is open."""
    from hystkit.parallel._contract import _CURRENT

    tokens = []
    yield lambda executor: tokens.append(_CURRENT.set(executor))
    for token in reversed(tokens):
        _CURRENT.reset(token)


def _head(rec: Recording, n: int) -> Recording:
    return Recording(time=rec.time[:n], sensor=rec.sensor[:n], position=rec.position[:n],
                     source=f"{rec.source}[:{n}]")


@pytest.fixture(scope="session")
def short_pair() -> tuple[Recording, Recording]:
    """Fit and validation recordings of the virtual sensor, 3000 samples each (small fits)."""
    return (_head(simulate_experiment("sine", 1), 3000),
            _head(simulate_experiment("sine", 2), 3000))
