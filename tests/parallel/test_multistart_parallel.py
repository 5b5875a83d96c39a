"""A fit's multi-start on two worker processes gives the serial fit bit for bit (issue 13), on
the default local executor (forked) and on a real two-process Dask cluster; the threshold that
keeps short fits serial; where the executor is current."""

from __future__ import annotations

import numpy as np
import pytest

import hystkit.identification._least_squares as least_squares
from hystkit.compensation import centre_and_scale
from hystkit.models import get_family
from hystkit.parallel import current_executor, open_executor
from hystkit.parallel._dask import DaskExecutor
from hystkit.parallel._forked import ForkedExecutor

# Families whose fits run fit_multistart with several starts, one per way of forming the
# normal equations: chua (finite differences, chunked), pl (variable projection), mpl
# (compiled sensitivities), boucwen (two stages).
FAMILIES = ("chua", "pl", "mpl", "boucwen")


@pytest.fixture
def split_on(parallel_executor, current):
    """A parallel executor (each kind in turn), current for the test as while it is open."""
    current(parallel_executor)
    return parallel_executor


@pytest.fixture
def fit_data(short_pair):
    """Normalised position -> sensor of 1500 samples (small fits)."""
    _, sensor, position = centre_and_scale(short_pair[0], "fit")
    return position[:1500], sensor[:1500], short_pair[0].dt


@pytest.fixture
def maps_run(monkeypatch):
    """Names of the functions each parallel map ran, with the number of pieces, in order."""
    calls = []
    for kind in (DaskExecutor, ForkedExecutor):
        def spy(self, func, items, _original=kind.map, **kwargs):
            calls.append((func.__name__, len(items)))
            return _original(self, func, items, **kwargs)

        monkeypatch.setattr(kind, "map", spy)
    return calls


def _fit(name: str, data) -> object:
    u, y, dt = data
    family = get_family(name)
    return family.fit(u, y, family.make_structure(dt, family.default_size))


@pytest.mark.parametrize("name", FAMILIES)
def test_split_multistart_equals_the_serial_fit(name, fit_data, split_on, maps_run,
                                                monkeypatch):
    monkeypatch.setattr(least_squares, "SPLIT_MIN_START", float("inf"))  # serial
    serial = _fit(name, fit_data)
    assert current_executor() is split_on and maps_run == []
    monkeypatch.setattr(least_squares, "SPLIT_MIN_START", 0.0)  # split every fit
    monkeypatch.setattr(least_squares, "SPLIT_MIN_SECONDS", 0.0)
    split = _fit(name, fit_data)
    assert maps_run and all(func == "_solve_start" for func, _ in maps_run)
    assert np.array_equal(split.theta, serial.theta)
    assert split.params == serial.params
    assert (split.cost, split.n_evaluations, split.converged, split.message) == \
        (serial.cost, serial.n_evaluations, serial.converged, serial.message)
    assert np.array_equal(split.sensitivity, serial.sensitivity)


def test_short_fits_stay_serial(fit_data, split_on, maps_run, monkeypatch):
    monkeypatch.setattr(least_squares, "SPLIT_MIN_START", float("inf"))
    _fit("chua", fit_data)
    assert maps_run == []


def test_few_short_starts_polish_side_by_side_only(fit_data, split_on, maps_run,
                                                   monkeypatch):
    monkeypatch.setattr(least_squares, "SPLIT_MIN_START", float("inf"))  # serial
    serial = _fit("chua", fit_data)
    monkeypatch.setattr(least_squares, "SPLIT_MIN_START", 0.0)
    monkeypatch.setattr(least_squares, "SPLIT_MIN_SECONDS", float("inf"))
    polished = _fit("chua", fit_data)
    assert maps_run and all(func == "_solve_start" and n <= 2 for func, n in maps_run)
    assert np.array_equal(polished.theta, serial.theta)
    assert polished.n_evaluations == serial.n_evaluations


def test_no_executor_is_current_inside_a_piece(split_on):
    # a piece runs in a worker, where nothing is open: a fit there stays serial
    assert current_executor() is split_on
    assert split_on.map(_current, [0, 1]) == [None, None]


@pytest.mark.parametrize("where", ["forked", "cluster"])
def test_the_executor_is_current_while_it_is_open(where, cluster_address):
    assert current_executor() is None
    with open_executor(**({"workers": 2} if where == "forked" else
                          {"scheduler": cluster_address})) as executor:
        assert current_executor() is executor
        with open_executor(1) as serial:  # a serial executor is never current
            assert current_executor() is executor and serial is not executor
    assert current_executor() is None


def _current(_: int):
    return current_executor()
