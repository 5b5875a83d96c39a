"""``--missing drop|interpolate|error`` (issue 27.1): an option of every command that reads
recordings (add_read_options) and a settings-file key; error by default, the rows touched
counted in one line; ``stream`` skips such lines and refuses ``interpolate``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hystkit.cli import main
from hystkit.io import write_recording
from hystkit.sensors import simulate_experiment

from ..cli_support import run_cli

HOLES = {"position": [100, 900], "sensor": [2000, 2001]}  # 4 rows inside


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("missing")
    rec = simulate_experiment("noise", seed=1)
    std = write_recording(rec, folder / "std.csv")
    frame = pd.read_csv(std)
    frame["temp"] = np.arange(len(frame))
    for column, rows in HOLES.items():
        frame[column] = frame[column].astype(object)
        frame.loc[rows, column] = ""
    holes = folder / "holes.csv"
    frame.to_csv(holes, index=False, float_format="%.17g")
    ends = frame.copy()
    ends.loc[:, "position"] = pd.read_csv(std)["position"]
    ends.loc[:, "sensor"] = pd.read_csv(std)["sensor"]
    ends = ends.astype({"position": object})
    ends.loc[[0, len(ends) - 1], "position"] = ""
    path_ends = folder / "ends.csv"
    ends.to_csv(path_ends, index=False, float_format="%.17g")
    return {"std": std, "holes": holes, "ends": path_ends, "n": len(frame)}


def test_fit_refuses_by_default_in_one_line_naming_the_option(files, tmp_path, capsys):
    code, _, err = run_cli(capsys, "fit", files["holes"], "--cells", 1, "--out",
                        tmp_path / "m.json")
    assert code == 2
    assert err.splitlines() == [
        (f"hystkit: error: {files['holes']}: column 'position', row 101 (line 102): empty "
        "cell (4 rows miss a value; --missing interpolate or --missing drop reads past them, "
        "or missing = \"interpolate\" in the settings file)")]


def test_fit_interpolates_and_says_how_many_rows(files, tmp_path, capsys):
    code, out, err = run_cli(capsys, "fit", files["holes"], "--cells", 1, "--no-band",
                          "--missing", "interpolate", "--out", tmp_path / "m.json")
    assert code == 0, err
    assert [line for line in err.splitlines() if "miss a value" in line] == [
        (f"hystkit: {files['holes']}: 4 of {files['n']} rows miss a value: 4 interpolated "
        "linearly in time (row 101 (line 102), row 901 (line 902), row 2001 (line 2002) and "
        "1 more)")]
    assert f"{files['n']} samples at 40 Hz" in out


def test_compensate_drops_rows_and_keeps_other_columns_aligned(files, tmp_path, capsys):
    model = tmp_path / "m.json"
    assert main(["fit", str(files["std"]), "--cells", "1", "--no-band", "--out",
                 str(model)]) == 0
    out_csv = tmp_path / "c.csv"
    code, _, err = run_cli(capsys, "compensate", model, files["ends"], "--missing", "drop",
                        "--out", out_csv)
    assert code == 0, err
    assert "2 of 8000 rows miss a value: 2 dropped (row 1 (line 2), row 8000 (line 8001))" \
        in err
    written = pd.read_csv(out_csv)
    assert len(written) == files["n"] - 2
    assert (written["temp"].to_numpy() == np.arange(1, files["n"] - 1)).all()


def test_settings_key_and_the_command_line_over_it(files, tmp_path, capsys):
    folder = tmp_path / "own"
    folder.mkdir()
    data = folder / "holes.csv"
    data.write_bytes(files["holes"].read_bytes())
    data.with_suffix(".toml").write_text('missing = "interpolate"\n')
    model = tmp_path / "m.json"
    code, out, err = run_cli(capsys, "fit", data, "--cells", 1, "--no-band", "--out", model)
    assert code == 0, err
    assert f"reading {data} with the settings in {data.with_suffix('.toml')}" in out
    assert "4 interpolated linearly in time" in err
    code, _, err = run_cli(capsys, "evaluate", model, data, "--missing", "error")
    assert code == 2 and "--missing interpolate or --missing drop reads past them" in err


def test_bad_value_is_refused_while_parsing(files, capsys):
    code, _, err = run_cli(capsys, "fit", files["holes"], "--missing", "fill")
    assert code == 2
    assert "argument --missing: invalid choice: 'fill'" in err


def test_stream_refuses_interpolate(files, tmp_path, capsys):
    model = tmp_path / "m.json"
    assert main(["fit", str(files["std"]), "--cells", "1", "--no-band", "--center", "track",
                 "--out", str(model)]) == 0
    code, out, err = run_cli(capsys, "stream", model, "--in", files["holes"], "--missing",
                          "interpolate")
    assert code == 2 and out == ""
    assert err.splitlines() == [
        ("hystkit: error: --missing interpolate: stream compensates the samples of a text "
        "input as they come (resample the file, or read it with compensate); a line missing "
        "a value is skipped and counted")]
