"""``--columns``, ``--time-unit``, ``--skip-rows``, ``--sep``: a user's own CSV (issue 11.1)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hystkit.cli import main

from ..cli_support import run_cli

OWN = ["--columns", "time=t_ms,position=displacement_mm,sensor=resistance_ohm",
       "--time-unit", "ms", "--sep", ";"]


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """The same recording twice: hystkit's names in s, and a user's names in ms with ';'."""
    folder = tmp_path_factory.mktemp("own")
    std = folder / "std.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(std)]) == 0
    frame = pd.read_csv(std)
    own = folder / "own.csv"
    pd.DataFrame({"t_ms": frame["time"] * 1e3, "displacement_mm": frame["position"],
                  "resistance_ohm": frame["sensor"]}).to_csv(own, sep=";", index=False)
    return {"std": std, "own": own, "folder": folder}


def test_fit_and_evaluate_own_csv_match_the_standard_file(files, tmp_path, capsys):
    scores = {}
    for name, extra in (("std", []), ("own", OWN)):
        model, report = tmp_path / f"{name}.json", tmp_path / f"{name}-scores.json"
        code, _, err = run_cli(capsys, "fit", files[name], "--cells", 1, "--out", model, *extra)
        assert code == 0, err
        code, _, err = run_cli(capsys, "evaluate", model, files[name], "--json", report, *extra)
        assert code == 0, err
        scores[name] = json.loads(report.read_text())
    assert scores["own"]["r2"] > 0.9
    for key in ("r2", "e_rms_pct", "e_max_pct", "n_samples"):
        assert scores["own"][key] == pytest.approx(scores["std"][key], rel=1e-6), key


def test_compensate_keeps_the_inputs_names_and_time_unit(files, tmp_path, capsys):
    model = tmp_path / "m.json"
    assert run_cli(capsys, "fit", files["own"], "--cells", 1, "--out", model, *OWN)[0] == 0
    out = tmp_path / "out.csv"
    code, _, err = run_cli(capsys, "compensate", model, files["own"], "--out", out, *OWN)
    assert code == 0, err
    written = pd.read_csv(out)
    assert list(written.columns[:4]) == ["t_ms", "displacement_mm", "resistance_ohm",
                                         "displacement_mm_estimate"]
    own = pd.read_csv(files["own"], sep=";")
    np.testing.assert_allclose(written["t_ms"], own["t_ms"], rtol=1e-12)


@pytest.mark.parametrize("option, fragments", [
    (["--columns", "time"], ["--columns", "NAME=COLUMN", "'time'"]),
    (["--columns", "pos=x"], ["--columns", "unknown name 'pos'"]),
    (["--columns", "time=a,sensor=a"], ["--columns", "time and sensor would both be read from column 'a'"]),
    (["--columns", "time=t,time=u"], ["--columns", "time is given 2 times"]),
    (["--time-unit", "h"], ["--time-unit", "invalid choice"]),
    (["--skip-rows", "-1"], ["--skip-rows"]),
    (["--sep", "|"], ["--sep", "'|'"]),
])
def test_bad_options_are_one_line_before_any_work(files, tmp_path, capsys, option, fragments):
    out = tmp_path / "m.json"
    code, stdout, err = run_cli(capsys, "fit", files["own"], "--out", out, *option)
    assert code == 2
    assert stdout == ""
    assert len(err.splitlines()) == 1 and err.startswith("hystkit: error: "), err
    for fragment in fragments:
        assert fragment in err, (fragment, err)
    assert not out.exists()


def test_unknown_column_names_the_users_column(files, tmp_path, capsys):
    out = tmp_path / "m.json"
    code, _, err = run_cli(capsys, "fit", files["own"], "--model", "mpl", "--out", out,
                        "--columns",
                        "time=t_ms,position=displacement_mm,sensor=R_ohm", "--time-unit", "ms",
                        "--sep", ";")
    assert code == 2
    expected = (f"hystkit: error: {files['own']}: missing required column 'R_ohm' (sensor); "
                "columns found: 't_ms', 'displacement_mm', 'resistance_ohm' (the first line "
                "must be a semicolon-separated header naming the columns)")
    assert err.splitlines() == [expected]
    assert not out.exists()


@pytest.mark.parametrize("command", ["fit", "evaluate", "compensate", "select", "compare"])
def test_every_reading_command_has_the_options(command, capsys):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for option in ("--columns", "--time-unit", "--skip-rows", "--sep"):
        assert option in text, (command, option)
    if command == "compensate":  # its output keeps the input's names (issue 27.4)
        assert "the output keeps the input's column names and time unit" in text
    else:
        assert "hystkit's column names (time [s], position, sensor" in text
