"""``hystkit stream`` writes in the input's names and time unit, as ``compensate`` does
(issue 27, item 4): the time column under its own name and unit, the estimate and band named
after the position column; a model that remembers how its training files were read reads a
file of their names, and stdin, that way."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_array_equal

from hystkit.cli import main

from ..cli_support import run_cli

OWN = ["--columns", "time=t_ms,position=x_mm,sensor=R_ohm", "--time-unit", "ms"]
HEADER = "t_ms,x_mm_estimate,flags,x_mm_lower,x_mm_upper"
SAID = "as the model's training data were read: columns t_ms,x_mm,R_ohm, time in ms"


@pytest.fixture(scope="module")
def lab(tmp_path_factory) -> dict[str, Path]:
    """A lab's training and validation runs (t_ms, x_mm, R_ohm; time in ms), a model fitted
    on the training run with the options (it remembers them) and compensate's output."""
    folder = tmp_path_factory.mktemp("names")
    files = {}
    for name, seed in (("train", 1), ("val", 2)):
        std = folder / f"{name}_std.csv"
        assert main(["simulate-sensor", "--excitation", "sine", "--seed", str(seed),
                     "--out", str(std)]) == 0
        frame = pd.read_csv(std).iloc[:600]
        own = pd.DataFrame({"t_ms": np.round(frame["time"] * 1e3), "x_mm": frame["position"],
                            "R_ohm": frame["sensor"]})
        own.to_csv(folder / f"{name}.csv", index=False)
        files[name] = folder / f"{name}.csv"
    files["model"] = folder / "model.json"
    assert main(["fit", str(files["train"]), *OWN, "--cells", "1", "--out",
                 str(files["model"])]) == 0
    files["compensated"] = folder / "c.csv"
    assert main(["compensate", str(files["model"]), str(files["val"]), "--out",
                 str(files["compensated"])]) == 0
    return files


def _same_as_compensate(out: str, lab: dict[str, Path], header: str = HEADER) -> None:
    """stream's output holds compensate's numbers bit for bit, in its names."""
    streamed = pd.read_csv(io.StringIO(out))
    assert ",".join(streamed.columns) == header
    written = pd.read_csv(lab["compensated"])
    names = header.split(",")
    assert_array_equal(streamed[names[0]].to_numpy(), pd.read_csv(lab["val"])["t_ms"])
    for column, kind in zip((names[1], names[3], names[4]), ("estimate", "lower", "upper"),
                            strict=True):
        assert_array_equal(streamed[column].to_numpy(), written[f"x_mm_{kind}"].to_numpy())


def test_a_file_read_as_trained_streams_in_its_own_names(lab, capsys):
    code, out, err = run_cli(capsys, "stream", lab["model"], "--in", lab["val"])
    assert code == 0, err
    assert f"hystkit stream: reading {lab['val']} {SAID}" in err.splitlines()
    _same_as_compensate(out, lab)


def test_stdin_is_read_as_trained_and_streams_in_its_own_names(lab, capsys, monkeypatch):
    monkeypatch.setattr("sys.stdin", io.StringIO(lab["val"].read_text(encoding="utf-8")))
    code, out, err = run_cli(capsys, "stream", lab["model"])
    assert code == 0, err
    assert (f"hystkit stream: reading <stdin> {SAID} (--columns and --time-unit read it "
            "otherwise)") in err.splitlines()
    assert "warning" not in err  # ms read as ms: no irregular step
    _same_as_compensate(out, lab)


def test_options_on_the_command_line_read_stdin_otherwise(lab, capsys, monkeypatch):
    """hystkit's own layout (seconds, its names) given explicitly: nothing remembered is
    applied, the output has hystkit's names, the numbers are the same."""
    val = pd.read_csv(lab["val"])
    seconds = "time,sensor\n" + "".join(f"{t / 1e3!r},{s!r}\n" for t, s in
                                        zip(val["t_ms"], val["R_ohm"], strict=True))
    monkeypatch.setattr("sys.stdin", io.StringIO(seconds))
    code, out, err = run_cli(capsys, "stream", lab["model"], "--columns",
                             "time=time,sensor=sensor", "--time-unit", "s")
    assert code == 0, err
    assert "training data were read" not in err and "warning" not in err
    streamed = pd.read_csv(io.StringIO(out))
    assert list(streamed.columns) == ["time", "position_estimate", "flags", "position_lower",
                                      "position_upper"]
    written = pd.read_csv(lab["compensated"])
    assert_array_equal(streamed["position_estimate"].to_numpy(),
                       written["x_mm_estimate"].to_numpy())


def test_a_model_that_remembers_nothing_keeps_hystkits_names(lab, tmp_path, capsys,
                                                             monkeypatch):
    model = tmp_path / "std.json"
    std = tmp_path / "train_std.csv"
    train = pd.read_csv(lab["train"])
    pd.DataFrame({"time": train["t_ms"] / 1e3, "position": train["x_mm"],
                  "sensor": train["R_ohm"]}).to_csv(std, index=False)
    assert run_cli(capsys, "fit", std, "--cells", 1, "--no-band", "--out", model)[0] == 0
    monkeypatch.setattr("sys.stdin", io.StringIO(std.read_text(encoding="utf-8")))
    code, out, err = run_cli(capsys, "stream", model)
    assert code == 0, err
    assert out.splitlines()[0] == "time,position_estimate,flags"
    assert "training data were read" not in err
