"""The sensor models and loop margins of ``hystkit control`` kept on disk (issue 29): a stored
result comes back bit for bit, and any change of the inputs or of the code computes again."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from hystkit import control as hc
from hystkit.control import _disk_cache
from hystkit.sensors import simulate_experiment


def _fake_fit(calls: list):
    """A stand-in for the fit that counts its calls (the real one takes about half a second)."""

    def fit(**options):
        calls.append(options)
        block = hc.linear_block(float(len(calls)))
        return hc.SensorModels(block, block, block, 1.0, {"fit": len(calls)})

    return fit


@pytest.fixture
def calls(monkeypatch) -> list:
    calls: list = []
    monkeypatch.setattr(_disk_cache, "fit_sensor_models", _fake_fit(calls))
    return calls


def _same_block(a: hc.SensorBlock, b: hc.SensorBlock, fields=("name", "info")) -> bool:
    fields = ("inverse", "in_offset", "in_scale", "out_offset", "out_scale", *fields)
    if any(getattr(a, f) != getattr(b, f) for f in fields) or a.structure != b.structure:
        return False
    return all(np.array_equal(getattr(a.params, f.name), getattr(b.params, f.name))
               for f in dataclasses.fields(a.params))


def test_the_stored_fit_comes_back_bit_for_bit(tmp_path, monkeypatch):
    options = {"sensor_cells": 1, "model_cells": 1}
    fitted = _disk_cache.cached_sensor_models(tmp_path, **options)
    assert len(list(tmp_path.glob("sensor-models-*.pickle"))) == 1

    def no_fit(**options):
        raise AssertionError("fitted again although stored")

    monkeypatch.setattr(_disk_cache, "fit_sensor_models", no_fit)
    read = _disk_cache.cached_sensor_models(tmp_path, **options)
    assert read is not fitted
    for slot in ("sensor", "compensator", "model"):
        assert _same_block(getattr(read, slot), getattr(fitted, slot)), slot
    assert read.sensor_gain == fitted.sensor_gain and read.info == fitted.info
    # and a fresh fit gives those numbers too (its info differs by the fit's seconds)
    fresh = hc.fit_sensor_models(**options)
    for slot in ("sensor", "compensator", "model"):
        assert _same_block(getattr(read, slot), getattr(fresh, slot), fields=()), slot


def test_the_same_inputs_fit_once_and_different_ones_again(tmp_path, calls):
    first = _disk_cache.cached_sensor_models(tmp_path, sensor_seed=1)
    again = _disk_cache.cached_sensor_models(tmp_path, sensor_seed=1)
    assert len(calls) == 1 and again.info == first.info
    _disk_cache.cached_sensor_models(tmp_path, sensor_seed=2)
    assert len(calls) == 2


def test_a_recording_is_keyed_by_its_values(tmp_path, calls):
    rec = simulate_experiment("sine", 2)
    _disk_cache.cached_sensor_models(tmp_path, training_recording=rec)
    _disk_cache.cached_sensor_models(tmp_path, training_recording=dataclasses.replace(rec))
    assert len(calls) == 1  # an equal recording, another object: found
    sensor = rec.sensor.copy()
    sensor[100] += 1e-12
    _disk_cache.cached_sensor_models(tmp_path,
                                      training_recording=dataclasses.replace(rec, sensor=sensor))
    assert len(calls) == 2  # one sample changed: fitted again


def test_a_change_of_the_code_fits_again(tmp_path, calls, monkeypatch):
    _disk_cache.cached_sensor_models(tmp_path)
    monkeypatch.setattr(_disk_cache, "code_stamp", lambda: "an edited source file")
    _disk_cache.cached_sensor_models(tmp_path)
    assert len(calls) == 2


def test_the_code_stamp_follows_a_source_file(tmp_path, monkeypatch):
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "a.py").write_text("x = 1\n")
    monkeypatch.setattr(_disk_cache, "PACKAGE", package)
    before = _disk_cache.code_stamp()
    assert _disk_cache.code_stamp() == before
    (package / "a.py").write_text("x = 22\n")
    assert _disk_cache.code_stamp() != before


def test_an_unreadable_entry_is_fitted_again_and_replaced(tmp_path, calls):
    _disk_cache.cached_sensor_models(tmp_path)
    (entry,) = tmp_path.glob("sensor-models-*.pickle")
    entry.write_bytes(b"not a pickle")
    models = _disk_cache.cached_sensor_models(tmp_path)
    assert len(calls) == 2 and models.info == {"fit": 2}
    assert _disk_cache.cached_sensor_models(tmp_path).info == {"fit": 2}
    assert len(calls) == 2


def test_an_unwritable_folder_still_fits(tmp_path, calls, capsys):
    blocked = tmp_path / "a file"
    blocked.write_text("")
    models = _disk_cache.cached_sensor_models(blocked)
    assert models.info == {"fit": 1}
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hystkit: not cached")


def test_the_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("HYSTKIT_CACHE_DIR", str(tmp_path / "here"))
    assert _disk_cache.cache_folder() == tmp_path / "here"
    monkeypatch.delenv("HYSTKIT_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert _disk_cache.cache_folder() == tmp_path / "xdg" / "hystkit"


def _linear_loop(kp: float = 545.0) -> hc.ControlLoop:
    sensor, comp = hc.linear_block(2.0, name="S_r"), hc.linear_block(0.5, name="comp")
    return hc.ControlLoop("direct", sensor, hc.PID(kp, 0.029, 0.0573), compensator=comp)


def test_stored_margins_are_the_computed_ones(tmp_path, monkeypatch):
    loop = _linear_loop()
    stored = _disk_cache.cached_loop_margins(loop, tmp_path)
    fresh = hc.loop_margins(loop)
    calls = []
    monkeypatch.setattr(hc, "loop_margins", lambda loop: calls.append(loop))
    read = _disk_cache.cached_loop_margins(_linear_loop(), tmp_path)  # an equal loop
    assert calls == []
    assert read == stored == fresh
    _disk_cache.cached_loop_margins(_linear_loop(kp=500.0), tmp_path)  # another gain
    assert len(calls) == 1
