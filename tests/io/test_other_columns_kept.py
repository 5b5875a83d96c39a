"""Other columns beside the recording (issue 11): carried through ``--resample`` like the
recording itself, and read from ``.mat`` structs, vectors and matrices."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.io import savemat

from hystkit.io import ReadOptions, read_other_columns, read_recording


def _jittered_csv(path, n=400, rate=40.0, seed=2):
    rng = np.random.default_rng(seed)
    time = np.arange(n) / rate + rng.uniform(-2e-3, 2e-3, n)
    sensor = np.sin(2 * np.pi * 0.5 * time) + 0.01 * rng.standard_normal(n)
    position = 3 * np.cos(2 * np.pi * 0.5 * time)
    lines = ["time,position,sensor,copy,ramp,note"]
    lines += [f"{t!r},{p!r},{s!r},{s!r},{2 * t + 1!r},{'x' if i == 0 else ''}"
              for i, (t, p, s) in enumerate(zip(time.tolist(), position.tolist(),
                                                sensor.tolist()))]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("rate", [40.0, 25.0, 10.0])  # same rate, mild and strong decimation
def test_resampled_column_goes_through_the_recordings_operations(tmp_path, rate):
    path = _jittered_csv(tmp_path / "j.csv")
    options = ReadOptions(resample_hz=rate)
    rec = read_recording(path, options=options)
    others = read_other_columns(path, rec.n_samples, options)
    assert list(others) == ["copy", "ramp"]  # the text column 'note' cannot be resampled
    # a copy of the sensor column is resampled to the very same bits as the sensor
    np.testing.assert_array_equal(others["copy"], rec.sensor)
    if rate == 40.0:  # linear interpolation is exact on a straight line
        np.testing.assert_allclose(others["ramp"], 2 * rec.time + 1, rtol=0, atol=1e-12)


def test_without_resampling_every_column_is_kept_as_read(tmp_path):
    path = _jittered_csv(tmp_path / "j.csv")
    frame_lines = path.read_text(encoding="utf-8").splitlines()
    fixed = [frame_lines[0]] + [",".join([f"{i / 40!r}"] + line.split(",")[1:])
                                for i, line in enumerate(frame_lines[1:])]
    path.write_text("\n".join(fixed) + "\n", encoding="utf-8")
    rec = read_recording(path)
    others = read_other_columns(path, rec.n_samples)
    assert list(others) == ["copy", "ramp", "note"]
    np.testing.assert_array_equal(others["copy"], rec.sensor)
    assert others["note"][0] == "x" and others["note"][1] == ""


def _rec(n=50):
    t = np.arange(n) * 0.025
    return t, np.sin(t), np.cos(t)


def test_mat_struct_keeps_its_other_vector_fields(tmp_path):
    t, p, s = _rec()
    path = tmp_path / "s.mat"
    savemat(path, {"run": {"t": t, "x": p, "R": s, "temp": 20 + t, "short": np.ones(3),
                           "label": "bench 2"}})
    options = ReadOptions(columns=(("time", "t"), ("position", "x"), ("sensor", "R")),
                          mat_var="run")
    rec = read_recording(path, options=options)
    others = read_other_columns(path, rec.n_samples, options)
    assert list(others) == ["temp"]  # not the 3-sample field, not the text
    np.testing.assert_array_equal(others["temp"], 20 + t)


def test_mat_top_level_vectors_and_the_only_struct(tmp_path):
    t, p, s = _rec()
    path = tmp_path / "v.mat"
    savemat(path, {"time": t, "position": p, "sensor": s, "trigger": (t > 0.5) * 1.0,
                   "units": {"time": "s"}})
    rec = read_recording(path)
    assert list(read_other_columns(path, rec.n_samples)) == ["trigger"]
    path2 = tmp_path / "only.mat"  # no --mat-var: the file's only struct holds the recording
    savemat(path2, {"rec": {"time": t, "position": p, "sensor": s, "temp": t * 2}})
    rec2 = read_recording(path2)
    np.testing.assert_array_equal(read_other_columns(path2, rec2.n_samples)["temp"], t * 2)


def test_mat_matrix_keeps_its_unnamed_columns(tmp_path):
    t, p, s = _rec()
    path = tmp_path / "m.mat"
    savemat(path, {"M": np.column_stack([t, s, p, t * 3])})
    options = ReadOptions(columns=(("time", "1"), ("position", "3"), ("sensor", "2")))
    rec = read_recording(path, options=options)
    others = read_other_columns(path, rec.n_samples, options)
    assert list(others) == ["column_4"]
    np.testing.assert_array_equal(others["column_4"], t * 3)
