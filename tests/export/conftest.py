"""Session fixtures of the export tests: the recordings and the compensators, built once."""

from __future__ import annotations

import pytest

from hystkit.compensation import Compensator
from hystkit.sensors import simulate_experiment

from .export_support import CASES, build_compensator


@pytest.fixture(scope="session")
def recordings():
    """Fitting conventions from a sine recording; validation on 8000 noise samples."""
    train = simulate_experiment("sine", seed=1)
    val = simulate_experiment("noise", seed=2)
    assert val.n_samples == 8000
    return train, val


@pytest.fixture(scope="session")
def compensators(recordings):
    """(label, mode, center) -> Compensator, built on first use."""
    cache: dict = {}
    train, val = recordings

    def get(label: str, mode: str, center: str) -> Compensator:
        key = (label, mode, center)
        if key not in cache:
            model, size = next((m, n) for lb, m, n in CASES if lb == label)
            cache[key] = build_compensator(train, val, model, size, mode, center)
        return cache[key]

    return get
