"""Session fixtures of the export tests: the recordings and the compensators, built once.

Under ``pytest -n`` (pytest-xdist) the C and the MATLAB test files usually run in different
workers, and each worker would fit the same ~60 compensators again (~20 s of CPU). The workers
of one run therefore share the compensators through a folder of the run's temporary root: the
first worker that needs one fits it and pickles it, the others wait for its lock and read it.
"""

from __future__ import annotations

import os
import pickle
from collections.abc import Callable
from contextlib import contextmanager
from pathlib import Path

import pytest

from hystkit.compensation import Compensator
from hystkit.sensors import simulate_experiment

from .export_support import CASES, build_compensator

try:
    import fcntl
except ImportError:  # Windows: each worker fits its own
    fcntl = None


@pytest.fixture(scope="session")
def recordings():
    """Fitting conventions from a sine recording; validation on 8000 noise samples."""
    train = simulate_experiment("sine", seed=1)
    val = simulate_experiment("noise", seed=2)
    assert val.n_samples == 8000
    return train, val


@contextmanager
def _locked(path: Path):
    with open(path, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _shared_folder(tmp_path_factory) -> Path | None:
    """The run's folder the xdist workers share (the parent of each worker's own temporary
    folder belongs to this run only); None without workers or without file locks."""
    if not os.environ.get("PYTEST_XDIST_WORKER") or fcntl is None:
        return None
    folder = tmp_path_factory.getbasetemp().parent / "export-compensators"
    folder.mkdir(exist_ok=True)
    return folder


def _built_once(folder: Path | None, key: tuple[str, str, str],
                build: Callable[[], Compensator]) -> Compensator:
    if folder is None:
        return build()
    stem = folder / "-".join(key)
    with _locked(stem.with_suffix(".lock")):
        done = stem.with_suffix(".pickle")
        if done.exists():
            return pickle.loads(done.read_bytes())
        comp = build()
        part = stem.with_suffix(".part")
        part.write_bytes(pickle.dumps(comp))
        os.replace(part, done)  # never a half-written file for the next worker
        return comp


@pytest.fixture(scope="session")
def compensators(recordings, tmp_path_factory):
    """(label, mode, center) -> Compensator, built on first use in this run."""
    cache: dict = {}
    train, val = recordings
    folder = _shared_folder(tmp_path_factory)

    def get(label: str, mode: str, center: str) -> Compensator:
        key = (label, mode, center)
        if key not in cache:
            model, size = next((m, n) for lb, m, n in CASES if lb == label)
            cache[key] = _built_once(folder, key, lambda: build_compensator(
                train, val, model, size, mode, center))
        return cache[key]

    return get
