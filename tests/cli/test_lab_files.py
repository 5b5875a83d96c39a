"""Commands read files as labs write them without reading options, and say what they detected
(issue 27.1): ';' or tab, a decimal comma, '#' comment lines before the header."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hystkit.cli import main

from ..cli_support import run_cli

OWN = ["--columns", "time=t_ms,position=displacement_mm,sensor=resistance_ohm",
       "--time-unit", "ms"]
NOTICE = "semicolon-separated, decimal comma, 2 comment lines before the header skipped"


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """The virtual sensor's sine as hystkit writes it, and as Excel in Europe saves it."""
    folder = tmp_path_factory.mktemp("lab")
    std = folder / "std.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(std)]) == 0
    frame = pd.read_csv(std)
    eu = pd.DataFrame({"t_ms": frame["time"] * 1e3, "displacement_mm": frame["position"],
                       "resistance_ohm": frame["sensor"],
                       "temp_C": np.round(20 + 0.01 * frame["time"], 3)})
    path = folder / "eu.csv"
    with open(path, "w", encoding="utf-8-sig", newline="") as out:
        out.write("# rig 3; gauge 7\r\n# exported 2026-11-30\r\n")
        eu.to_csv(out, sep=";", decimal=",", index=False, lineterminator="\r\n",
                  float_format="%.17g")
    return {"std": std, "eu": path}


def test_fit_evaluate_compensate_read_the_excel_file_as_the_standard_one(files, tmp_path,
                                                                         capsys):
    scores = {}
    for name, extra in (("std", []), ("eu", OWN)):
        model, report = tmp_path / f"{name}.json", tmp_path / f"{name}-scores.json"
        code, out, err = run_cli(capsys, "fit", files[name], "--cells", 1, "--out", model, *extra)
        assert code == 0, err
        said = [line for line in out.splitlines() if line.startswith(f"reading {files[name]}")]
        assert said == ([f"reading {files['eu']}: {NOTICE}"] if name == "eu" else [])
        code, _, err = run_cli(capsys, "evaluate", model, files[name], "--json", report, *extra)
        assert code == 0, err
        scores[name] = json.loads(report.read_text())
    assert scores["eu"]["r2"] > 0.9
    for key in ("r2", "e_rms_pct", "n_samples"):
        # %.17g through a decimal comma: the same numbers, so the same scores to rounding
        assert scores["eu"][key] == pytest.approx(scores["std"][key], rel=1e-9), key
    out = tmp_path / "comp.csv"
    code, _, err = run_cli(capsys, "compensate", tmp_path / "eu.json", files["eu"], "--out", out,
                        *OWN)
    assert code == 0, err
    written = pd.read_csv(out)
    assert written["temp_C"].dtype == np.float64  # '20,01' kept as the number 20.01
    np.testing.assert_allclose(written["temp_C"].iloc[:3], [20.0, 20.0, 20.0], atol=1e-3)


def test_a_given_separator_still_wins(files, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(capsys, "fit", files["eu"], "--cells", 1, "--out", "never.json",
                        "--sep", ",", *OWN)
    assert code == 2
    assert err.splitlines() == [
        (f"hystkit: error: {files['eu']}: missing required column 't_ms' (time), "
         "'displacement_mm' (position), 'resistance_ohm' (sensor); columns found: "
         "'t_ms;displacement_mm;resistance_ohm;temp_C' (line 3, below the comments, "
         "must be a comma-separated header naming the columns)")]
    assert not Path("never.json").exists()


def test_an_ambiguous_file_is_one_line_naming_file_line_and_option(tmp_path, capsys):
    path = tmp_path / "odd.csv"
    path.write_text("time;position,sensor\n0;1,2\n0.1;2,3\n", encoding="utf-8")
    code, _, err = run_cli(capsys, "fit", path, "--cells", 1, "--out", tmp_path / "m.json")
    assert code == 2
    assert err.splitlines() == [
        (f"hystkit: error: {path}: line 1: cannot tell the field separator: comma and "
         "semicolon each split the header and the 2 line(s) below it alike; pass --sep ',' "
         "or --sep ';' (or sep = \"...\" in the settings file)")]
    assert not (tmp_path / "m.json").exists()
