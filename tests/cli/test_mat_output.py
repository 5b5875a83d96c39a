"""Answers out in MATLAB: model files, compensated recordings and scores as ``.mat`` (issue 11).

Files are read back with scipy's `loadmat` (and with Octave when it is installed, as an
independent reader) and compared with the JSON/CSV outputs of the same run.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_array_equal
from scipy.io import loadmat, savemat

from hystkit.cli import main
from hystkit.compensation import compensator_to_dict, load_compensator, save_compensator
from hystkit.errors import InputError, NonFiniteError
from hystkit.io import read_recording, write_mat

from ..cli_support import run_cli


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> dict[str, Path]:
    """A recording, its model fitted once as JSON, and the same model saved as .mat."""
    folder = tmp_path_factory.mktemp("matout")
    rec = folder / "rec.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(rec)]) == 0
    model = folder / "m.json"
    assert main(["fit", str(rec), "--cells", "1", "--out", str(model)]) == 0
    mat_model = folder / "m.mat"
    save_compensator(load_compensator(model), mat_model)
    return {"folder": folder, "rec": rec, "json": model, "mat": mat_model}


def test_model_mat_round_trip_is_exact(run):
    original = compensator_to_dict(load_compensator(run["json"]))
    again = compensator_to_dict(load_compensator(run["mat"]))
    assert json.dumps(again, sort_keys=True) == json.dumps(original, sort_keys=True)


def test_model_mat_holds_every_field_for_matlab(run):
    d = json.loads(run["json"].read_text())
    m = loadmat(run["mat"], simplify_cells=True)
    assert set(d) <= set(m)
    assert m["model"] == d["model"] and m["mode"] == d["mode"]
    assert m["dt"] == d["dt"]
    for name, value in d["params"].items():  # numbers and numeric lists as doubles
        assert_array_equal(np.ravel(m["params"][name]), np.ravel(value))
    assert json.loads(m["hystkit_json"]) == d


def test_fit_writes_a_mat_model_that_evaluate_and_compensate_read(run, tmp_path, capsys):
    model = tmp_path / "fit.mat"
    code, _, err = run_cli(capsys, "fit", run["rec"], "--cells", 1, "--out", model)
    assert code == 0, err
    for kind in ("json", "mat"):
        path = run[kind] if kind == "json" else model
        code, _, err = run_cli(capsys, "evaluate", path, run["rec"], "--json",
                            tmp_path / f"{kind}.json")
        assert code == 0, err
    scores = [json.loads((tmp_path / f"{k}.json").read_text()) for k in ("json", "mat")]
    # the same data, the same fit: the .mat model scores as the JSON one to rounding
    assert scores[1]["r2"] == pytest.approx(scores[0]["r2"], rel=1e-9)


def test_edited_mat_model_is_refused(run, tmp_path):
    m = loadmat(run["mat"])
    m = {k: v for k, v in m.items() if not k.startswith("__")}
    params = m["params"][0, 0]
    edited = {name: params[name] * 2 for name in params.dtype.names}
    m["params"] = edited
    path = tmp_path / "edited.mat"
    savemat(path, m)
    with pytest.raises(InputError, match=r"params\.\w+ differs from the model in "
                                         r"'hystkit_json'"):
        load_compensator(path)


def test_mat_without_model_text_is_one_line(tmp_path):
    path = tmp_path / "other.mat"
    savemat(path, {"x": np.ones(3)})
    with pytest.raises(InputError, match=r"not a hystkit model file .*variables: x"):
        load_compensator(path)


def test_compensate_to_mat_matches_csv(run, tmp_path, capsys):
    csv, mat = tmp_path / "c.csv", tmp_path / "c.mat"
    for out in (csv, mat):
        code, _, err = run_cli(capsys, "compensate", run["json"], run["rec"], "--out", out)
        assert code == 0, err
    frame = pd.read_csv(csv)
    m = loadmat(mat)
    for column in frame.columns:
        assert m[column].shape == (len(frame), 1), column  # column vectors
        assert_array_equal(m[column][:, 0].astype(float), frame[column].to_numpy(float))
    assert m["sensor_outside"].dtype == np.uint8  # logical in MATLAB (scipy reads uint8)
    names = [str(c[0]) for c in m["column_names"][0]]
    assert names == list(frame.columns)
    back = read_recording(mat)  # hystkit reads its own .mat output
    assert_array_equal(back.sensor, frame["sensor"].to_numpy())


def test_evaluate_out_mat_equals_json(run, tmp_path, capsys):
    js, mat = tmp_path / "e.json", tmp_path / "e.mat"
    code, _, err = run_cli(capsys, "evaluate", run["json"], run["rec"], "--json", js, "--out", mat)
    assert code == 0, err
    scores = json.loads(js.read_text())
    m = loadmat(mat, simplify_cells=True)
    for key, value in scores.items():
        if value is None:
            assert np.size(m[key]) == 0, key  # [] in MATLAB
        elif isinstance(value, str | dict):  # text, units (a struct)
            assert m[key] == value, key
        else:
            assert float(m[key]) == value, key


def test_write_mat_refuses_nan_and_clashing_names(tmp_path):
    with pytest.raises(NonFiniteError, match=r"a\.mat: value fit\.se\[1\] is nan"):
        write_mat(tmp_path / "a.mat", {"fit": {"se": [1.0, float("nan")]}})
    with pytest.raises(ValueError, match="both become MATLAB variable 'a_b'"):
        write_mat(tmp_path / "b.mat", {"a b": 1, "a_b": 2})
    assert list(tmp_path.iterdir()) == []


def test_write_mat_types(tmp_path):
    path = write_mat(tmp_path / "t.mat", {"n": 3, "flag": True, "text": "mm", "none": None,
                                          "row": [1, 2.5], "grid": [[1, 2], [3, 4]],
                                          "mixed": ["a", 1], "s": {"temp C": 20.5}})
    m = loadmat(path, simplify_cells=True)
    assert m["n"] == 3.0 and m["flag"] == 1 and m["text"] == "mm" and m["none"].size == 0
    assert_array_equal(m["row"], [1, 2.5])
    assert_array_equal(m["grid"], [[1, 2], [3, 4]])
    assert list(m["mixed"]) == ["a", 1.0]
    assert m["s"]["temp_C"] == 20.5  # names become MATLAB identifiers


@pytest.mark.skipif(shutil.which("octave") is None, reason="octave is not installed")
def test_octave_reads_the_outputs(run, tmp_path, capsys):
    out = tmp_path / "c.mat"
    assert run_cli(capsys, "compensate", run["mat"], run["rec"], "--out", out)[0] == 0
    script = (f"c = load('{out}'); m = load('{run['mat']}'); "
              "printf('%s %d %d %s\\n', class(c.sensor_outside), numel(c.position_estimate), "
              "isstruct(m.params), m.model);")
    proc = subprocess.run(["octave", "--no-gui", "--quiet", "--eval", script],
                          capture_output=True, text=True, timeout=120, check=False)
    line = [x for x in proc.stdout.splitlines() if x.strip()][-1]
    n = len(pd.read_csv(run["rec"]))
    assert line.split() == ["logical", str(n), "1", json.loads(run["json"].read_text())["model"]]
