"""Worker start-up: the command's set-up (the kernels loaded) once before the fork, not again in
each forked worker."""

from __future__ import annotations

import numpy as np
import pytest

import hystkit.parallel._dask as dask_executor
from hystkit.models import FAMILIES, _warm


def test_the_warm_up_signal_fits_every_family():
    """Each family's fit runs to the end on it, so its fit kernels are loaded (a fit that
    fails early would leave them to every worker)."""
    u = 0.8 * np.sin(np.linspace(0, 6 * np.pi, 150)) * np.linspace(1.0, 0.5, 150)
    y = 0.6 * u + 0.4 * _warm._play(u, 0.15)
    for family in FAMILIES.values():
        result = family.fit(u, y, family.make_structure(1 / 40, family.default_size))
        assert np.isfinite(result.cost)


def test_the_play_operator_follows_the_input_within_its_radius():
    u = np.array([0.0, 0.5, 1.0, 0.9, 0.5, -0.5, -0.4])
    y = _warm._play(u, 0.2)
    # y(t) = clip(y(t-1), u - r, u + r) from 0: flat inside the band, r behind outside it
    assert np.allclose(y, [0.0, 0.3, 0.8, 0.8, 0.7, -0.3, -0.3])
    assert np.all(np.abs(y - u) <= 0.2 + 1e-15)


@pytest.mark.parametrize("ran_here", [True, False])
def test_dask_workers_run_the_setup_only_if_they_did_not_inherit_it(ran_here, monkeypatch):
    calls = []

    def setup():
        calls.append(1)

    monkeypatch.setattr(dask_executor, "_RUN_HERE", set())
    monkeypatch.setattr(dask_executor, "threadpool_limits", lambda limits: None)
    if ran_here:  # as in a worker forked from a process that ran it
        dask_executor.run_setup(setup)
        calls.clear()
    dask_executor.WorkerSetup(setup).setup(worker=None)
    assert calls == ([] if ran_here else [1])
    dask_executor.WorkerSetup(setup).setup(worker=None)  # a second plugin start: not again
    assert calls == ([] if ran_here else [1])


def test_a_worker_without_a_setup_only_limits_blas(monkeypatch):
    limits = []
    monkeypatch.setattr(dask_executor, "threadpool_limits", limits.append)
    dask_executor.WorkerSetup().setup(worker=None)
    assert limits == [1]
