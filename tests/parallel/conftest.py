"""One real Dask cluster for the parallel tests: two spawned worker processes, as a cluster
started outside hystkit would have (hystkit reaches it with ``--scheduler``)."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import pytest

from hystkit.io import Recording
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="session")
def cluster_address() -> Iterator[str]:
    distributed = pytest.importorskip("distributed")
    from hystkit.parallel._dask import NO_DASHBOARD

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  silence_logs=logging.CRITICAL, **NO_DASHBOARD) as cluster:
        yield cluster.scheduler_address


def _head(rec: Recording, n: int) -> Recording:
    return Recording(time=rec.time[:n], sensor=rec.sensor[:n], position=rec.position[:n],
                     source=f"{rec.source}[:{n}]")


@pytest.fixture(scope="session")
def short_pair() -> tuple[Recording, Recording]:
    """Fit and validation recordings of the virtual sensor, 3000 samples each (small fits)."""
    return (_head(simulate_experiment("sine", 1), 3000),
            _head(simulate_experiment("sine", 2), 3000))
