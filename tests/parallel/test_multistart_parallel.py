"""A fit's multi-start on a real two-process local Dask cluster gives the serial fit bit for
bit (issue 13); the threshold that keeps short fits serial; where the executor is current."""

from __future__ import annotations

import numpy as np
import pytest

import hystkit.identification._least_squares as least_squares
from hystkit.compensation import centre_and_scale
from hystkit.models import get_family
from hystkit.parallel import current_executor, open_executor
from hystkit.parallel._dask import DaskExecutor

# Families whose fits run fit_multistart with several starts, one per way of forming the
# normal equations: chua (finite differences, chunked), pl (variable projection), mpl
# (compiled sensitivities), boucwen (two stages).
FAMILIES = ("chua", "pl", "mpl", "boucwen")


@pytest.fixture(scope="module")
def forked_cluster():
    """`open_executor(2)`: a local cluster of two forked worker processes, kept open."""
    pytest.importorskip("distributed")
    with open_executor(2) as executor:
        assert isinstance(executor, DaskExecutor) and executor.n_workers == 2
        yield executor


@pytest.fixture
def fit_data(short_pair):
    """Normalised position -> sensor of 1500 samples (small fits)."""
    _, sensor, position = centre_and_scale(short_pair[0], "fit")
    return position[:1500], sensor[:1500], short_pair[0].dt


@pytest.fixture
def maps_run(monkeypatch):
    """Names of the functions each DaskExecutor.map ran, in call order."""
    calls = []
    original = DaskExecutor.map

    def spy(self, func, items, **kwargs):
        calls.append((func.__name__, len(items)))
        return original(self, func, items, **kwargs)

    monkeypatch.setattr(DaskExecutor, "map", spy)
    return calls


def _fit(name: str, data) -> object:
    u, y, dt = data
    family = get_family(name)
    return family.fit(u, y, family.make_structure(dt, family.default_size))


@pytest.mark.parametrize("name", FAMILIES)
def test_split_multistart_equals_the_serial_fit(name, fit_data, forked_cluster, maps_run,
                                                monkeypatch):
    serial = _fit(name, fit_data)
    assert current_executor() is forked_cluster
    monkeypatch.setattr(least_squares, "SPLIT_MIN_START", 0.0)  # split every fit
    monkeypatch.setattr(least_squares, "SPLIT_MIN_SECONDS", 0.0)
    split = _fit(name, fit_data)
    assert maps_run and all(func == "_solve_start" for func, _ in maps_run)
    assert np.array_equal(split.theta, serial.theta)
    assert split.params == serial.params
    assert (split.cost, split.n_evaluations, split.converged, split.message) == \
        (serial.cost, serial.n_evaluations, serial.converged, serial.message)
    assert np.array_equal(split.sensitivity, serial.sensitivity)


def test_short_fits_stay_serial(fit_data, forked_cluster, maps_run, monkeypatch):
    monkeypatch.setattr(least_squares, "SPLIT_MIN_START", float("inf"))
    _fit("chua", fit_data)
    assert maps_run == []


def test_few_short_starts_polish_side_by_side_only(fit_data, forked_cluster, maps_run,
                                                   monkeypatch):
    serial = _fit("chua", fit_data)
    monkeypatch.setattr(least_squares, "SPLIT_MIN_START", 0.0)
    monkeypatch.setattr(least_squares, "SPLIT_MIN_SECONDS", float("inf"))
    polished = _fit("chua", fit_data)
    assert maps_run and all(func == "_solve_start" and n <= 2 for func, n in maps_run)
    assert np.array_equal(polished.theta, serial.theta)
    assert polished.n_evaluations == serial.n_evaluations


def test_the_executor_is_current_only_where_it_is_open(forked_cluster):
    # inside a piece (a worker's thread) nothing is open: a fit there stays serial
    assert forked_cluster.map(_current, [0, 1]) == [None, None]
    with open_executor(1) as serial:
        assert current_executor() is forked_cluster and serial is not forked_cluster


def test_the_executor_is_current_while_it_is_open(cluster_address):
    before = current_executor()
    with open_executor(scheduler=cluster_address) as executor:
        assert current_executor() is executor
    assert current_executor() is before


def _current(_: int):
    return current_executor()
