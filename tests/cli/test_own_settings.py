"""A user's file with its settings beside it (``my.csv`` + ``my.toml``), a units line, extra
columns: read, carried through fit/evaluate/compensate, written back (issue 11)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_array_equal
from scipy.io import loadmat

from hystkit.cli import main
from hystkit.errors import InputError
from hystkit.io import ReadOptions, options_for, read_recording, read_recording_config

from ..cli_support import run_cli

SETTINGS = """time_unit = "ms"
units_row = true
sep = ";"

[columns]
time = "t_ms"
position = "displacement_mm"
sensor = "resistance_ohm"

[units]
temp_C = "degC"
"""
OWN = ["--columns", "time=t_ms,position=displacement_mm,sensor=resistance_ohm",
       "--time-unit", "ms", "--sep", ";", "--units-row"]


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """The simulated sine as a user's CSV: own names, ms, ';', a units line, two more
    columns (a temperature with one empty cell, a text note)."""
    folder = tmp_path_factory.mktemp("settings")
    std = folder / "std.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(std)]) == 0
    frame = pd.read_csv(std)
    temp = np.linspace(20, 21, len(frame))
    temp[5] = np.nan
    own = pd.DataFrame({"t_ms": frame["time"] * 1e3, "displacement_mm": frame["position"],
                        "resistance_ohm": frame["sensor"], "temp_C": temp,
                        "note": ["start"] + [""] * (len(frame) - 1)})
    data = {}
    for name in ("with_toml", "plain"):
        path = folder / name / "my.csv"
        path.parent.mkdir()
        with path.open("w", encoding="utf-8") as f:
            f.write("t_ms;displacement_mm;resistance_ohm;temp_C;note\nms;mm;Ohm;degC;\n")
            own.to_csv(f, sep=";", index=False, header=False)
        data[name] = path
    (folder / "with_toml" / "my.toml").write_text(SETTINGS, encoding="utf-8")
    data["std"] = std
    data["own"] = own
    return data


def test_settings_file_reads_as_the_options(files):
    by_file, settings = options_for(files["with_toml"])
    assert settings == files["with_toml"].with_suffix(".toml")
    rec = read_recording(files["with_toml"], options=by_file)
    by_cli = read_recording(files["plain"], options=ReadOptions(
        columns={"time": "t_ms", "position": "displacement_mm", "sensor": "resistance_ohm"},
        time_unit="ms", sep=";", units_row=True))
    std = read_recording(files["std"])
    for a in (rec, by_cli):
        assert_array_equal(a.position, std.position)
        assert_array_equal(a.sensor, std.sensor)
        np.testing.assert_allclose(a.time, std.time, rtol=1e-15, atol=0)  # ms -> s, 1 rounding
        assert dict(a.units) == {"position": "mm", "sensor": "Ohm"}


def test_fit_with_settings_file_equals_fit_with_options(files, tmp_path, capsys):
    code, out, err = run_cli(capsys, "fit", files["with_toml"], "--cells", 1, "--out",
                          tmp_path / "a.json")
    assert code == 0, err
    assert out.count("with the settings in") == 1
    code, out, err = run_cli(capsys, "fit", files["plain"], "--cells", 1, "--out",
                          tmp_path / "b.json", *OWN)
    assert code == 0, err
    assert "with the settings in" not in out
    a, b = (json.loads((tmp_path / n).read_text()) for n in ("a.json", "b.json"))
    assert a["params"] == b["params"]
    assert a["fit"]["units"] == {"position": "mm", "sensor": "Ohm"}


def test_command_line_overrides_the_settings_file(tmp_path, files, capsys):
    folder = tmp_path / "wrong"
    folder.mkdir()
    data = folder / "my.csv"
    data.write_bytes(files["with_toml"].read_bytes())
    (folder / "my.toml").write_text(SETTINGS.replace('"ms"', '"s"'), encoding="utf-8")
    code, _, err = run_cli(capsys, "fit", data, "--cells", 1, "--out", tmp_path / "m.json")
    assert code == 2 and "the file gives the time unit 'ms' but time is read in s" in err
    code, _, err = run_cli(capsys, "fit", data, "--cells", 1, "--time-unit", "ms", "--out",
                        tmp_path / "m.json")
    assert code == 0, err


@pytest.mark.parametrize("text, fragments", [
    ('units_row = "yes"\n', ["key 'units_row' must be bool"]),
    ('columns = 3\n', ["key 'columns' must be dict"]),
    ('time_unit = 3\n', ["key 'time_unit' must be str"]),
    ('time_unit = "h"\n', ["time_unit must be one of"]),
    ('[columns]\nvoltage = "v"\n', ["'columns.voltage'"]),
    ('sep = \n', ["invalid TOML"]),
])
def test_bad_settings_file_is_one_line(tmp_path, files, capsys, text, fragments):
    data = tmp_path / "x.csv"
    data.write_bytes(files["std"].read_bytes())
    (tmp_path / "x.toml").write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as info:
        options_for(data)
    assert str(info.value).startswith(str(tmp_path / "x.toml"))
    for fragment in fragments:
        assert fragment in str(info.value)
    code, _, err = run_cli(capsys, "fit", data, "--model", "mpl", "--out", tmp_path / "m.json")
    assert code == 2 and len(err.strip().splitlines()) == 1


def test_forgotten_units_row_says_so(files, tmp_path, capsys):
    argv = [a for a in OWN if a != "--units-row"]
    code, _, err = run_cli(capsys, "fit", files["plain"], *argv, "--model", "mpl", "--out",
                           tmp_path / "m.json")
    assert code == 2
    assert "row 1 (line 2): non-numeric value 'ms'; if this line holds units, pass " \
           "--units-row" in err


def test_compensate_keeps_other_columns_and_units(files, tmp_path, capsys):
    model = tmp_path / "m.json"
    assert run_cli(capsys, "fit", files["with_toml"], "--cells", 1, "--out", model)[0] == 0
    out = tmp_path / "c.csv"
    code, stdout, err = run_cli(capsys, "compensate", model, files["with_toml"], "--out", out)
    assert code == 0, err
    assert "displacement_mm_estimate' [mm]" in stdout and "kept 2 other column(s)" in stdout
    written = pd.read_csv(out, keep_default_na=False, na_values=[""])
    # the input's names, the estimate and its band named after its position column
    assert list(written.columns) == ["t_ms", "displacement_mm", "resistance_ohm", "temp_C",
                                     "note", "displacement_mm_estimate",
                                     "displacement_mm_lower", "displacement_mm_upper",
                                     "sensor_outside", "estimate_outside"]
    own = files["own"]
    assert_array_equal(written["temp_C"].to_numpy(), own["temp_C"].to_numpy())  # NaN kept
    assert written["note"].fillna("").tolist() == own["note"].tolist()
    # the units (and names, time unit) went into c.toml, which reading c.csv picks up again
    back, settings = options_for(out)
    assert settings == tmp_path / "c.toml"
    assert dict(read_recording(out, options=back).units) == {"position": "mm",
                                                              "sensor": "Ohm"}
    assert dict(back.units)["displacement_mm_estimate"] == "mm"
    assert dict(back.units)["temp_C"] == "degC"
    mat = tmp_path / "c.mat"
    assert run_cli(capsys, "compensate", model, files["with_toml"], "--out", mat)[0] == 0
    m = loadmat(mat, simplify_cells=True)
    assert m["units"] == {"t_ms": "ms", "displacement_mm": "mm", "resistance_ohm": "Ohm",
                          "displacement_mm_estimate": "mm", "displacement_mm_lower": "mm",
                          "displacement_mm_upper": "mm", "temp_C": "degC"}
    assert_array_equal(m["temp_C"], own["temp_C"].to_numpy())
    # a cell array of text; scipy reads an empty char as an empty array
    notes = [x if isinstance(x, str) else ("" if np.size(x) == 0 else x) for x in m["note"]]
    assert notes == own["note"].tolist()
    assert_array_equal(m["displacement_mm_estimate"],
                       written["displacement_mm_estimate"].to_numpy())


def test_compensate_refuses_an_existing_units_file_before_work(files, tmp_path, capsys):
    model = tmp_path / "m.json"
    assert run_cli(capsys, "fit", files["with_toml"], "--cells", 1, "--out", model)[0] == 0
    (tmp_path / "c.toml").write_text("precious\n")
    code, _, err = run_cli(capsys, "compensate", model, files["with_toml"], "--out",
                        tmp_path / "c.csv")
    assert code == 2 and "c.toml already exists" in err
    assert not (tmp_path / "c.csv").exists()


def test_evaluate_reports_units(files, tmp_path, capsys):
    model = tmp_path / "m.json"
    assert run_cli(capsys, "fit", files["with_toml"], "--cells", 1, "--out", model)[0] == 0
    code, _, err = run_cli(capsys, "evaluate", model, files["with_toml"], "--json",
                        tmp_path / "e.json")
    assert code == 0, err
    scores = json.loads((tmp_path / "e.json").read_text())
    assert scores["units"] == {"position": "mm", "sensor": "Ohm"}


def test_a_raw_recordings_settings_of_the_same_stem_are_left_alone(files, tmp_path, capsys):
    # preprocess turns run.parquet (+ run.toml, its raw settings) into run.csv beside them
    data = tmp_path / "run.csv"
    data.write_bytes(files["std"].read_bytes())
    (tmp_path / "run.toml").write_text('r_bridge = 100.0\n\n[columns]\nv1 = "A"\n',
                                       encoding="utf-8")
    options, settings = options_for(data)
    assert settings is None and options == ReadOptions()
    code, out, err = run_cli(capsys, "fit", data, "--cells", 1, "--out", tmp_path / "m.json")
    assert code == 0, err
    assert "with the settings in" not in out
    with pytest.raises(InputError, match="key 'r_bridge' .*raw scope files.*preprocess"):
        read_recording_config(tmp_path / "run.toml")  # named when read as a recording's


def test_compensate_with_resample_leaves_out_text_and_gappy_columns(files, tmp_path, capsys):
    model = tmp_path / "m.json"
    assert run_cli(capsys, "fit", files["with_toml"], "--cells", 1, "--out", model)[0] == 0
    out = tmp_path / "c.csv"
    code, stdout, err = run_cli(capsys, "compensate", model, files["with_toml"], "--resample", 40,
                             "--out", out)
    assert code == 0, err
    assert "columns with text or empty cells cannot be and are left out" in stdout
    written = pd.read_csv(out)
    assert "temp_C" not in written.columns and "note" not in written.columns  # empty cell; text
    # the file is uniform at 40 Hz already: resampled at its own rate it is the same recording
    # up to rounding (its times are ms x 1e-3, the grid's t0 + k / 40: a few ulp apart)
    np.testing.assert_allclose(written["resistance_ohm"].to_numpy(),
                               files["own"]["resistance_ohm"].to_numpy(), rtol=0, atol=1e-13)


def test_the_python_api_reads_the_settings_file_as_the_command_line_does(files, tmp_path):
    import hystkit as hk

    by_file = hk.read(files["with_toml"])  # my.toml beside it: names, ms, ';', units line
    std = read_recording(files["std"])
    assert_array_equal(by_file.sensor, std.sensor)
    assert dict(by_file.units) == {"position": "mm", "sensor": "Ohm"}
    with pytest.raises(InputError, match="time is read in s"):  # given overrides the file's
        hk.read(files["with_toml"], time_unit="s")
    with pytest.raises(InputError, match="missing required column"):  # no settings file
        hk.read(files["plain"])
    with pytest.raises(TypeError, match="time_units"):
        hk.read(files["with_toml"], time_units="ms")
    comp = hk.fit(files["with_toml"], "mpl", size=1)
    assert comp.params == hk.fit(std, "mpl", size=1).params


def test_report_reads_each_recording_with_its_settings_file(files, tmp_path, capsys):
    model = tmp_path / "m.json"
    assert main(["fit", str(files["std"]), "--cells", "1", "--out", str(model)]) == 0
    figures = tmp_path / "f"
    code, out, err = run_cli(capsys, "report", model, files["with_toml"], "--out",
                          tmp_path / "r.html", "--figures", figures, "--format", "svg")
    assert code == 0, err
    assert "with the settings in" in out
    # the user's sensor name and unit (from the units line the settings file asks for)
    assert "resistance_ohm [Ohm]" in (figures / "loops.svg").read_text(encoding="utf-8")
    code, _, err = run_cli(capsys, "report", model, files["plain"], "--out", tmp_path / "p.html")
    assert code == 2 and "missing required column" in err


def test_pl_search_and_stability_read_the_settings_file(files, tmp_path, capsys):
    grid = ["--n", 1, "--p", 2, "--m", 2, "--s", 0, "--workers", 1]
    found = []
    for data in (files["with_toml"], files["std"]):
        code, out, err = run_cli(capsys, "pl-search", data, *grid)
        assert code == 0, err
        found.append([line for line in out.splitlines() if line.startswith("best:")])
    assert found[0] == found[1] and found[0]
    model = tmp_path / "m.json"
    assert main(["fit", str(files["std"]), "--cells", "1", "--out", str(model)]) == 0
    steps = []
    for data, options in ((files["with_toml"], []), (files["plain"], OWN), (files["std"], [])):
        code, out, err = run_cli(capsys, "stability", model, "--data", data, *options)
        assert code == 0, err
        steps.append([line for line in out.splitlines() if "eigenvalues" in line])
    assert steps[0] == steps[1] == steps[2] and steps[0]
    code, _, err = run_cli(capsys, "pl-search", files["plain"], *grid)
    assert code == 2 and "missing required column" in err


def test_control_reads_its_training_recording_with_the_settings_file(files, tmp_path, capsys):
    metrics = []
    for name, data, options in (("own", files["with_toml"], []), ("cli", files["plain"], OWN),
                                ("std", files["std"], [])):
        out = tmp_path / name
        code, _, err = run_cli(capsys, "control", "--scheme", "direct", "--experiment", "sine",
                            "--training-data", data, *options, "--out", out)
        assert code == 0, err
        table = json.loads((out / "metrics.json").read_text())
        metrics.append({k: v for k, v in table["cases"]["sine"].items()
                        if not k.endswith("seconds")})
    assert metrics[0] == metrics[1] == metrics[2]
