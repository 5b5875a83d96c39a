"""Worker start-up: kernels loaded once before the fork, not again in each forked worker."""

from __future__ import annotations

import numpy as np
import pytest

import hystkit.parallel._dask as dask_executor
from hystkit.models import FAMILIES
from hystkit.parallel import _warm


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


@pytest.mark.parametrize("warmed", [True, False])
def test_dask_workers_warm_only_if_they_did_not_inherit_the_kernels(warmed, monkeypatch):
    calls = []
    monkeypatch.setattr(_warm, "_warmed", warmed)
    monkeypatch.setattr(_warm, "warm_kernels", lambda: calls.append(1))
    monkeypatch.setattr("threadpoolctl.threadpool_limits", lambda limits: None)
    dask_executor.WorkerSetup().setup(worker=None)
    assert calls == ([] if warmed else [1])
