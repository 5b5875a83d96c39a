"""The notebook interface ``import hystkit as hk`` (issue 11, part 4): lazy, DataFrame in and
out, and the same numbers as the library functions it wraps."""

from __future__ import annotations

import doctest
import importlib
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import hystkit as hk
from hystkit.compensation import evaluate, fit_compensator
from hystkit.errors import InputError
from hystkit.io import ReadOptions, Recording, read_recording
from hystkit.sensors import simulate_experiment

HEAVY = ("numpy", "pandas", "scipy", "numba", "matplotlib")
DOCTESTED = ("hystkit._api", "hystkit._api_reading", "hystkit.io._recording",
             "hystkit.io._time_column", "hystkit.compensation._estimator", "hystkit.cli._inputs")


def _loaded_after(code: str) -> list[str]:
    probe = f"{code}\nimport sys\nprint(','.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, timeout=120).stdout.strip()
    return [m for m in out.split(",") if m]


def test_import_hystkit_loads_nothing_heavy():
    assert _loaded_after("import hystkit") == []


@pytest.mark.parametrize("module", DOCTESTED)
def test_docstring_examples_run(module, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # examples write own.csv and model.json
    result = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0, result


def test_lazy_names_resolve_and_unknown_ones_fail():
    for name in hk.__all__:
        assert getattr(hk, name) is not None
        assert name in dir(hk)
    assert hk.models.FAMILIES is hk.FAMILIES
    with pytest.raises(AttributeError, match="no attribute 'no_such_thing'"):
        _ = hk.no_such_thing


def test_family_package_exports_its_public_names():
    """What ``from hystkit.models.pi import *`` binds: every name of ``__all__``."""
    package = importlib.import_module("hystkit.models.pi")
    namespace = {name: getattr(package, name) for name in package.__all__}
    from hystkit.models.pi import model

    assert set(model.__all__) <= set(namespace)
    assert namespace["PiStructure"] is model.PiStructure
    assert namespace["FAMILY"].Structure is model.PiStructure


@pytest.fixture(scope="module")
def recs():
    return simulate_experiment("noise", seed=1), simulate_experiment("noise", seed=2)


def test_frame_round_trip_is_identity(recs):
    rec = recs[0]
    back = Recording.from_frame(rec.to_frame())
    for name in ("time", "position", "sensor"):
        assert_array_equal(getattr(back, name), getattr(rec, name))
    no_position = Recording(time=rec.time, sensor=rec.sensor)
    assert list(no_position.to_frame().columns) == ["time", "sensor"]
    assert Recording.from_frame(no_position.to_frame()).position is None


def test_from_frame_maps_columns_and_converts_time(recs):
    rec = recs[0]
    frame = pd.DataFrame({"t_ms": rec.time * 1e3, "x": rec.position, "r": rec.sensor})
    mapped = Recording.from_frame(frame, columns={"time": "t_ms", "position": "x",
                                                  "sensor": "r"}, time_unit="ms")
    assert_allclose(mapped.time, rec.time, rtol=1e-15, atol=0)
    with pytest.raises(InputError, match=r"missing column 'r' \(sensor\)"):
        Recording.from_frame(frame.drop(columns="r"), columns={"time": "t_ms", "sensor": "r"})
    frame = frame.astype({"r": object})
    frame.loc[3, "r"] = "oops"
    with pytest.raises(InputError, match=r"column 'r' \(sensor\), sample 4: not a number"):
        Recording.from_frame(frame, columns={"time": "t_ms", "position": "x", "sensor": "r"},
                             time_unit="ms")


def test_read_is_read_recording_with_read_options(recs, tmp_path):
    rec = recs[0]
    path = tmp_path / "own.csv"
    pd.DataFrame({"t": rec.time * 1e3, "x_mm": rec.position, "r": rec.sensor}).to_csv(
        path, index=False)
    columns = {"time": "t", "position": "x_mm", "sensor": "r"}
    got = hk.read(path, columns=columns, time_unit="ms")
    want = read_recording(path, options=ReadOptions(columns=columns, time_unit="ms"))
    for name in ("time", "position", "sensor"):
        assert_array_equal(getattr(got, name), getattr(want, name))


def test_fit_evaluate_compensate_match_the_library(recs, tmp_path):
    """A DataFrame, a Recording and a path give the same compensator as fit_compensator."""
    fit_rec, val_rec = recs
    want = fit_compensator(fit_rec, 1)
    path = tmp_path / "fit.csv"
    fit_rec.to_frame().to_csv(path, index=False)
    for data in (fit_rec, fit_rec.to_frame(), path):
        assert hk.fit(data, "mpl", size=1).params == want.params
    scores = hk.evaluate(want, val_rec.to_frame())
    assert scores == evaluate(want, val_rec)
    keys = list(scores)
    assert keys.index("r2") < keys.index("linear_r2") < keys.index("center_oracle") < \
        keys.index("r2_oracle")
    out = hk.compensate(want, val_rec)
    assert_array_equal(out["position_estimate"].to_numpy(), want.estimate(val_rec))
    assert out["sensor_outside"].dtype == bool
    saved = hk.save(want, tmp_path / "model.json")
    assert_array_equal(hk.load(saved).estimate(val_rec), want.estimate(val_rec))
    with pytest.raises(TypeError, match="expected a Recording, a DataFrame or a file path"):
        hk.fit(42)


def test_compare_table_scores_the_same_compensator(recs):
    """Row ``mpl``'s deployable direct R² is that of hk.fit + hk.evaluate (another path)."""
    fit_rec, val_rec = recs
    table = hk.compare(fit_rec, val_rec, models=["mpl"])
    assert isinstance(table, pd.DataFrame) and table.index.tolist() == ["mpl"]
    direct = hk.evaluate(hk.fit(fit_rec, "mpl"), val_rec)["r2"]
    assert table.loc["mpl", "r2_direct"] == pytest.approx(direct, abs=1e-9)
    assert np.isfinite(table.loc["mpl", "r2_forward"])
