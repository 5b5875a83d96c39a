"""``hystkit stream --in FILE`` reads a file as ``fit`` does (issue 27.2): its settings file,
the reading options, the detected layout; and a stream that compensates nothing is an error
naming the file and the line, never a silent exit 0."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.cli import main
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.live import Stream
from hystkit.sensors import simulate_experiment

N = 60
OWN = ["--columns", "time=t_ms,sensor=R_ohm", "--time-unit", "ms", "--units-row"]


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stream_lab")
    comp = fit_compensator(simulate_experiment("noise", 1), 1, center="track", diagnose=False)
    return comp, save_compensator(comp, folder / "noise.json")


@pytest.fixture(scope="module")
def run():
    return simulate_experiment("decay", 2)


def _eu_file(path: Path, rec, settings: bool) -> Path:
    """`rec` as Excel in Europe saves a logger's export: comments, ';', decimal commas, ms,
    a units line, its own names, a temperature column between."""
    lines = ["# logger 4, channel R", "# 2026-11-30", "t_ms;temp_C;R_ohm", "ms;degC;Ohm"]
    lines += [f"{float(t) * 1e3!r};20,5;{float(s)!r}".replace(".", ",")
              for t, s in zip(rec.time[:N], rec.sensor[:N])]
    path.write_text("\r\n".join(lines) + "\r\n", encoding="utf-8-sig")
    if settings:
        path.with_suffix(".toml").write_text(
            'time_unit = "ms"\nunits_row = true\n\n[columns]\ntime = "t_ms"\nsensor = "R_ohm"\n',
            encoding="utf-8")
    return path


def _output(text: str, time: str = "t_ms") -> tuple[np.ndarray, np.ndarray]:
    """Times and estimates of stream's output, whose header names the input's time column
    (``compensate``'s names, issue 27.4)."""
    rows = text.splitlines()
    assert rows[0] == f"{time},position_estimate,flags"
    fields = [row.split(",") for row in rows[1:]]
    return np.array([float(f[0]) for f in fields]), np.array([float(f[1]) for f in fields])


@pytest.mark.parametrize("settings", [True, False])
def test_a_lab_file_streams_as_fit_reads_it(model, run, tmp_path, capsys, settings):
    comp, path = model
    data = _eu_file(tmp_path / "eu.csv", run, settings)
    capsys.readouterr()
    assert main(["stream", str(path), "--in", str(data), *([] if settings else OWN)]) == 0
    captured = capsys.readouterr()
    times, estimate = _output(captured.out)
    assert_array_equal(estimate, Stream(comp).process(run.sensor[:N]))  # bit for bit
    assert_array_equal(times, run.time[:N] * 1e3)  # echoed in ms, as in the file
    err = captured.err.splitlines()
    said = [(f"hystkit stream: reading {data}: semicolon-separated, decimal comma, 2 comment "
             "lines before the header skipped")]
    if settings:
        said.insert(0, f"hystkit stream: reading {data} with the settings in "
                       f"{data.with_suffix('.toml')}")
    assert err[:len(said)] == said
    assert "warning" not in captured.err


def test_stdin_takes_the_reading_options(model, run, capsys, monkeypatch):
    comp, path = model
    lines = ["t_ms;R_ohm"] + [f"{float(t) * 1e3!r};{float(s)!r}".replace(".", ",")
                              for t, s in zip(run.time[:N], run.sensor[:N])]
    monkeypatch.setattr("sys.stdin", io.StringIO("\n".join(lines) + "\n"))
    capsys.readouterr()
    assert main(["stream", str(path), "--sep", ";", "--decimal", ",", "--columns",
                 "time=t_ms,sensor=R_ohm", "--time-unit", "ms"]) == 0
    _, estimate = _output(capsys.readouterr().out)
    assert_array_equal(estimate, Stream(comp).process(run.sensor[:N]))


def test_a_header_without_the_columns_is_one_error_line_naming_the_fix(model, run, tmp_path,
                                                                       capsys):
    _, path = model
    data = _eu_file(tmp_path / "eu.csv", run, settings=False)
    capsys.readouterr()
    assert main(["stream", str(path), "--in", str(data)]) == 2
    captured = capsys.readouterr()
    assert captured.err.splitlines()[-1] == (
        f"hystkit: error: {data}: line 3: a header without the columns 'time' (time) and "
        "'sensor' (sensor); found 't_ms', 'temp_C', 'R_ohm': name them with --columns "
        "time=NAME,sensor=NAME (or in the settings file), or check --sep")


def test_a_file_whose_every_line_is_skipped_is_an_error_not_exit_0(model, tmp_path, capsys):
    _, path = model
    data = tmp_path / "bad.csv"
    data.write_text("time,sensor\n0.0,x\n0.025,y\n0.05,\n", encoding="utf-8")
    capsys.readouterr()
    assert main(["stream", str(path), "--in", str(data)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[-1] == (f"hystkit: error: {data}: no sample compensated: every one of 3 line(s) "
                       "was skipped, the first at line 2: not a number (is the input laid out "
                       "as the options say? --sep, --columns, --time-unit)")
    data.write_text("time,sensor\n\n", encoding="utf-8")
    assert main(["stream", str(path), "--in", str(data)]) == 2
    assert capsys.readouterr().err.splitlines()[-1] == (
        f"hystkit: error: {data}: no sample compensated: the input held no data line")


def test_resampling_is_refused_before_reading(model, tmp_path, capsys):
    _, path = model
    capsys.readouterr()
    assert main(["stream", str(path), "--resample", "40"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.splitlines() == [
        ("hystkit: error: --resample: stream compensates the samples of a text input as they "
         "come (resample the file, or read it with compensate)")]


def test_a_comma_file_with_its_own_names_is_refused_not_misread(model, run, tmp_path, capsys):
    # read as time,sensor the columns would be t_ms and displacement: refused at line 1
    _, path = model
    data = tmp_path / "my.csv"
    data.write_text("t_ms,displacement_mm,resistance_ohm\n" + "".join(
        f"{float(t) * 1e3!r},0.5,{float(s)!r}\n" for t, s in zip(run.time[:N], run.sensor[:N])),
        encoding="utf-8")
    capsys.readouterr()
    assert main(["stream", str(path), "--in", str(data)]) == 2
    assert capsys.readouterr().err.splitlines()[-1].startswith(
        f"hystkit: error: {data}: line 1: a header without the columns 'time' (time) and "
        "'sensor' (sensor); found 't_ms', 'displacement_mm', 'resistance_ohm'")


def test_blank_lines_in_a_rewritten_file_stay_blank(model, run, tmp_path, capsys):
    comp, path = model
    data = _eu_file(tmp_path / "eu.csv", run, settings=True)
    lines = data.read_text(encoding="utf-8-sig").splitlines(keepends=True)
    data.write_text("".join(lines[:10] + ["\r\n"] + lines[10:]), encoding="utf-8")
    capsys.readouterr()
    assert main(["stream", str(path), "--in", str(data)]) == 0
    captured = capsys.readouterr()
    assert_array_equal(_output(captured.out)[1], Stream(comp).process(run.sensor[:N]))
    assert "warning" not in captured.err
