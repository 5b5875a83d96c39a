"""The model file remembers how its training data were read (issue 27, item 3), and
``compensate`` writes in the input's names and time unit (item 4).

A lab's CSV and ``.mat`` (columns ``t_ms``, ``x_mm``, ``R_ohm``, time in ms) are fitted once
with ``--columns``/``--time-unit``; ``evaluate``, ``compensate``, ``report`` and
``stream --in`` then read files of that layout without any option, as the same files in
hystkit's own names and seconds are read.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_array_equal
from scipy.io import loadmat, savemat

from hystkit.cli import main

from ..cli_support import run_cli

COLUMNS = "time=t_ms,position=x_mm,sensor=R_ohm"
OWN = ["--columns", COLUMNS, "--time-unit", "ms"]
SAID = "as the model's training data were read: columns t_ms,x_mm,R_ohm, time in ms"
OUTPUT = ["t_ms", "x_mm", "R_ohm", "x_mm_estimate", "x_mm_lower", "x_mm_upper",
          "sensor_outside", "estimate_outside"]


def _own(frame: pd.DataFrame) -> pd.DataFrame:
    """hystkit's recording as the lab writes it: its names, time in ms (whole numbers)."""
    return pd.DataFrame({"t_ms": np.round(frame["time"] * 1e3), "x_mm": frame["position"],
                         "R_ohm": frame["sensor"]})


@pytest.fixture(scope="module")
def lab(tmp_path_factory) -> dict[str, Path]:
    """Training and validation runs of the virtual sine, in hystkit's layout and the lab's
    (CSV and .mat), and a model fitted on the lab's training CSV with the options."""
    folder = tmp_path_factory.mktemp("lab")
    files = {}
    for name, seed in (("train", 1), ("val", 2)):
        std = folder / f"{name}_std.csv"
        assert main(["simulate-sensor", "--excitation", "sine", "--seed", str(seed),
                     "--out", str(std)]) == 0
        own = _own(pd.read_csv(std))
        own.to_csv(folder / f"{name}.csv", index=False)
        files[f"{name}_std"] = std
        files[name] = folder / f"{name}.csv"
    val = pd.read_csv(files["val"])
    savemat(folder / "val.mat", {c: val[c].to_numpy() for c in val.columns}, oned_as="column")
    files["val_mat"] = folder / "val.mat"
    files["model"] = folder / "model.json"
    assert main(["fit", str(files["train"]), *OWN, "--cells", "1",
                 "--out", str(files["model"])]) == 0
    return files


def test_fit_writes_how_it_read_into_the_model_file(lab):
    stored = json.loads(lab["model"].read_text())["reading"]
    assert stored == {"columns": {"time": "t_ms", "position": "x_mm", "sensor": "R_ohm"},
                      "time_unit": "ms", "units_row": False}


def test_compensate_without_options_reads_as_trained_and_writes_the_inputs_names(
        lab, tmp_path, capsys):
    out, std_out = tmp_path / "c.csv", tmp_path / "std.csv"
    code, stdout, err = run_cli(capsys, "compensate", lab["model"], lab["val"], "--out", out)
    assert code == 0, err
    assert f"reading {lab['val']} {SAID}" in stdout.splitlines()
    assert "'x_mm_estimate'" in stdout and "'x_mm_lower', 'x_mm_upper'" in stdout
    written = pd.read_csv(out)
    assert list(written.columns) == OUTPUT
    val = pd.read_csv(lab["val"])
    for column in ("t_ms", "x_mm", "R_ohm"):  # as in the input, time in ms
        assert_array_equal(written[column].to_numpy(), val[column].to_numpy())
    # the same run in hystkit's names: read as it is, written as today, the same estimate
    code, stdout, err = run_cli(capsys, "compensate", lab["model"], lab["val_std"], "--out",
                             std_out)
    assert code == 0, err
    assert "training data were read" not in stdout
    std = pd.read_csv(std_out)
    assert list(std.columns) == ["time", "position", "sensor", "position_estimate",
                                 "position_lower", "position_upper", "sensor_outside",
                                 "estimate_outside"]
    for kind in ("estimate", "lower", "upper"):
        assert_array_equal(written[f"x_mm_{kind}"].to_numpy(),
                           std[f"position_{kind}"].to_numpy())


def test_the_settings_written_beside_the_output_read_it_back(lab, tmp_path, capsys):
    out = tmp_path / "c.csv"
    assert run_cli(capsys, "compensate", lab["model"], lab["val"], "--out", out)[0] == 0
    settings = (tmp_path / "c.toml").read_text(encoding="utf-8")
    assert 'time_unit = "ms"' in settings and '"sensor" = "R_ohm"' in settings
    code, stdout, err = run_cli(capsys, "evaluate", lab["model"], out, "--json",
                             tmp_path / "back.json")
    assert code == 0, err
    assert f"reading {out} with the settings in {tmp_path / 'c.toml'}" in stdout
    code, _, err = run_cli(capsys, "evaluate", lab["model"], lab["val"], "--json",
                        tmp_path / "val.json")
    assert code == 0, err
    back, val = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("back", "val"))
    assert back["r2"] == val["r2"] and back["n_samples"] == val["n_samples"]


def test_evaluate_without_options_scores_as_with_them(lab, tmp_path, capsys):
    scores = {}
    for name, extra in (("remembered", []), ("given", OWN)):
        path = tmp_path / f"{name}.json"
        code, stdout, err = run_cli(capsys, "evaluate", lab["model"], lab["val"], *extra,
                                 "--json", path)
        assert code == 0, err
        # the command line's --columns describes the file: nothing remembered is applied
        assert (SAID in stdout) == (name == "remembered"), stdout
        scores[name] = json.loads(path.read_text())
    for key in ("r2", "e_rms_pct", "e_max_pct", "n_samples", "band_coverage"):
        assert scores["remembered"][key] == scores["given"][key], key


def test_a_mat_file_of_the_same_names_in_and_out(lab, tmp_path, capsys):
    out = tmp_path / "c.mat"
    code, stdout, err = run_cli(capsys, "compensate", lab["model"], lab["val_mat"], "--out", out)
    assert code == 0, err
    assert f"reading {lab['val_mat']} {SAID}" in stdout.splitlines()
    m = loadmat(out, simplify_cells=True)
    assert list(m["column_names"]) == OUTPUT
    assert {name for name in m if not name.startswith("__")} == {*OUTPUT, "column_names",
                                                                 "units"}
    val = pd.read_csv(lab["val"])
    assert_array_equal(m["t_ms"], val["t_ms"].to_numpy())  # c.t_ms in ms
    assert_array_equal(m["R_ohm"], val["R_ohm"].to_numpy())  # c.R_ohm, case kept
    assert m["units"] == {"t_ms": "ms"}  # the training files gave no units


def test_a_model_fitted_on_the_mat_file_reads_the_csv(lab, tmp_path, capsys):
    model = tmp_path / "m.mat"
    code, _, err = run_cli(capsys, "fit", lab["val_mat"], *OWN, "--cells", 1, "--no-band",
                        "--out", model)
    assert code == 0, err
    path = tmp_path / "scores.json"
    code, stdout, err = run_cli(capsys, "evaluate", model, lab["train"], "--json", path)
    assert code == 0, err
    assert f"reading {lab['train']} {SAID}" in stdout.splitlines()
    assert json.loads(path.read_text())["n_samples"] == len(pd.read_csv(lab["train"]))


def test_parquet_output_keeps_the_names_and_time_unit(lab, tmp_path, capsys):
    out = tmp_path / "c.parquet"
    assert run_cli(capsys, "compensate", lab["model"], lab["val"], "--out", out)[0] == 0
    written = pd.read_parquet(out)
    assert list(written.columns) == OUTPUT
    assert_array_equal(written["t_ms"].to_numpy(), pd.read_csv(lab["val"])["t_ms"].to_numpy())


def test_an_old_model_file_without_the_key_still_works(lab, tmp_path, capsys):
    data = json.loads(lab["model"].read_text())
    del data["reading"]
    old = tmp_path / "old.json"
    old.write_text(json.dumps(data), encoding="utf-8")
    # nothing remembered: the lab's file needs its options, as before
    code, _, err = run_cli(capsys, "evaluate", old, lab["val"])
    assert code == 2 and "missing required column 'time'" in err
    out = tmp_path / "c.csv"
    code, stdout, err = run_cli(capsys, "compensate", old, lab["val"], *OWN, "--out", out)
    assert code == 0, err
    assert "training data were read" not in stdout
    assert list(pd.read_csv(out).columns) == OUTPUT


def test_an_explicit_option_wins_over_the_remembered_one(tmp_path, capsys):
    """A model trained on ``t`` in ms; the same layout in seconds is read in s only with
    --time-unit s: the remembered ms would make it 40 kHz, which the model refuses."""
    frames = {}
    for name, seed, scale in (("train", 1, 1e3), ("val", 2, 1.0)):
        std = tmp_path / f"{name}_std.csv"
        assert main(["simulate-sensor", "--excitation", "sine", "--seed", str(seed),
                     "--out", str(std)]) == 0
        frame = pd.read_csv(std)
        frames[name] = pd.DataFrame({"t": frame["time"] * scale, "x": frame["position"],
                                     "r": frame["sensor"]})
        frames[name].to_csv(tmp_path / f"{name}.csv", index=False)
    model = tmp_path / "m.json"
    code, _, err = run_cli(capsys, "fit", tmp_path / "train.csv", "--columns",
                        "time=t,position=x,sensor=r", "--time-unit", "ms", "--cells", 1,
                        "--no-band", "--out", model)
    assert code == 0, err
    code, _, err = run_cli(capsys, "compensate", model, tmp_path / "val.csv", "--out",
                        tmp_path / "wrong.csv")
    assert code == 2 and "sampled every 2.5e-05 s, but the model was fitted at 0.025 s" in err
    out = tmp_path / "c.csv"
    code, stdout, err = run_cli(capsys, "compensate", model, tmp_path / "val.csv",
                             "--time-unit", "s", "--out", out)
    assert code == 0, err
    assert (f"reading {tmp_path / 'val.csv'} as the model's training data were read: "
            f"columns t,x,r, time in s") in stdout
    written = pd.read_csv(out)
    assert list(written.columns[:4]) == ["t", "x", "r", "x_estimate"]
    assert_array_equal(written["t"].to_numpy(), frames["val"]["t"].to_numpy())  # in s


def test_a_settings_file_of_its_own_wins(lab, tmp_path, capsys):
    data = tmp_path / "val.csv"
    data.write_bytes(lab["val"].read_bytes())
    (tmp_path / "val.toml").write_text('time_unit = "ms"\n\n[columns]\ntime = "t_ms"\n'
                                       'position = "x_mm"\nsensor = "R_ohm"\n\n[units]\n'
                                       'position = "um"\n', encoding="utf-8")
    code, stdout, err = run_cli(capsys, "evaluate", lab["model"], data, "--json",
                             tmp_path / "s.json")
    assert code == 0, err
    assert f"reading {data} with the settings in {tmp_path / 'val.toml'}" in stdout
    assert "training data were read" not in stdout
    assert json.loads((tmp_path / "s.json").read_text())["units"] == {"position": "um"}


def test_a_units_line_is_read_where_the_file_has_one(tmp_path, capsys):
    std = tmp_path / "std.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(std)]) == 0
    own = _own(pd.read_csv(std))
    with_units = tmp_path / "with_units.csv"
    with with_units.open("w", encoding="utf-8") as f:
        f.write("t_ms,x_mm,R_ohm\nms,mm,Ohm\n")
        own.to_csv(f, index=False, header=False)
    plain = tmp_path / "plain.csv"
    own.to_csv(plain, index=False)
    model = tmp_path / "m.json"
    code, _, err = run_cli(capsys, "fit", with_units, *OWN, "--units-row", "--cells", 1,
                        "--no-band", "--out", model)
    assert code == 0, err
    assert json.loads(model.read_text())["reading"]["units_row"] is True
    for path, said in ((with_units, f"{SAID}, a units line"), (plain, SAID)):
        out = tmp_path / f"{path.stem}-out.csv"
        code, stdout, err = run_cli(capsys, "compensate", model, path, "--out", out)
        assert code == 0, err
        assert f"reading {path} {said}" in stdout.splitlines(), stdout
        assert "'x_mm_estimate' [mm]" in stdout  # the training position's unit
        assert_array_equal(pd.read_csv(out)["t_ms"].to_numpy(), own["t_ms"].to_numpy())


def test_stream_in_and_report_read_as_trained(lab, tmp_path, capsys):
    code, stdout, err = run_cli(capsys, "stream", lab["model"], "--in", lab["val"])
    assert code == 0, err
    assert f"hystkit stream: reading {lab['val']} {SAID}" in err.splitlines()
    rows = stdout.splitlines()
    assert len(rows) == len(pd.read_csv(lab["val"])) + 1  # the header, then every sample
    code, stdout, err = run_cli(capsys, "report", lab["model"], lab["val"], "--out",
                             tmp_path / "r.html")
    assert code == 0, err
    assert f"reading {lab['val']} {SAID}" in stdout.splitlines()


def test_files_read_differently_are_not_remembered(lab, tmp_path, capsys):
    own = tmp_path / "own.csv"
    own.write_bytes(lab["train"].read_bytes())
    (tmp_path / "own.toml").write_text('time_unit = "ms"\n\n[columns]\ntime = "t_ms"\n'
                                       'position = "x_mm"\nsensor = "R_ohm"\n',
                                       encoding="utf-8")
    model = tmp_path / "m.json"
    code, stdout, err = run_cli(capsys, "fit", own, lab["val_std"], "--cells", 1, "--no-band",
                             "--out", model)
    assert code == 0, err
    assert "note: the training files were read differently" in stdout
    assert json.loads(model.read_text())["reading"] is None
