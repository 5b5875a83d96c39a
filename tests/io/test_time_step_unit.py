"""A time column in ms or us read as seconds (issue 27.1): a name that states a unit is
checked against the one read (``t_ms`` read in s is refused); a name that says nothing is
judged by its step: a rate of 1 Hz or lower gets one warning line naming the column and the
``--time-unit`` that would make it plausible. The numbers stay as read: never a guess."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_array_equal

import hystkit as hk
from hystkit.cli import main
from hystkit.errors import InputError
from hystkit.io import ReadOptions, read_recording
from hystkit.io._cells import Where as _Where
from hystkit.io._time_column import time_step_warning
from hystkit.sensors import simulate_experiment


def _write(path: Path, time: np.ndarray, name: str = "time") -> Path:
    rng = np.random.default_rng(2)
    u = np.sin(np.linspace(0, 6 * np.pi, time.size))
    lines = [f"{name},position,sensor"]
    lines += [f"{t!r},{3 * x!r},{x + 1e-3 * e!r}"
              for t, x, e in zip(time.tolist(), u.tolist(), rng.standard_normal(time.size).tolist())]
    path.write_text("\n".join(lines) + "\n")
    return path


def _warning_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("hystkit: warning:")]


@pytest.mark.parametrize("step, unit", [(1.0, "ms"), (20.0, "ms"), (999.0, "ms"),
                                        (1000.0, "us"), (20_000.0, "us"), (5e6, "ns")])
def test_integer_steps_read_as_seconds_are_warned_once(tmp_path, capsys, step, unit):
    path = _write(tmp_path / "log.csv", np.arange(100) * step)
    capsys.readouterr()
    rec = read_recording(path)
    lines = _warning_lines(capsys.readouterr().err)
    expected = (f"hystkit: warning: {path}: column 'time': one sample every {step:.6g} s "
                f"({1 / step:.6g} Hz) read in s; if the time is in {unit}, pass "
                f"--time-unit {unit} (or time_unit = \"{unit}\" in the settings file)")
    assert lines == [expected]
    assert_array_equal(rec.time, np.arange(100) * step)  # warned, not changed


def test_the_suggested_unit_reads_without_a_warning(tmp_path, capsys):
    path = _write(tmp_path / "log.csv", np.arange(100) * 25.0)
    capsys.readouterr()
    rec = read_recording(path, options=ReadOptions(time_unit="ms"))
    assert rec.fs == pytest.approx(40.0, rel=1e-12)
    assert _warning_lines(capsys.readouterr().err) == []


@pytest.mark.parametrize("name, options", [
    ("time", {}),                                     # 40 Hz in s: plausible
    ("time_s", {"columns": {"time": "time_s"}}),      # the name says s: taken as meant
    ("t [sec]", {"columns": {"time": "t [sec]"}}),
    ("time", {"time_unit": "min"}),                   # a slow log, said so
])
def test_plausible_or_stated_time_is_not_warned(tmp_path, capsys, name, options):
    step = 1.5 if options.get("time_unit") == "min" or name != "time" else 0.025
    path = _write(tmp_path / "log.csv", np.arange(100) * step, name)
    capsys.readouterr()
    read_recording(path, options=ReadOptions(**options))
    assert capsys.readouterr().err == ""


def test_ms_read_as_ms_with_us_steps_is_warned(tmp_path, capsys):
    path = _write(tmp_path / "log.csv", np.arange(100) * 25_000.0)  # us, read as ms
    capsys.readouterr()
    read_recording(path, options=ReadOptions(time_unit="ms"))
    expected = (f"hystkit: warning: {path}: column 'time': one sample every 25 s (0.04 Hz) "
                "read in ms; if the time is in us, pass --time-unit us (or time_unit = \"us\" "
                "in the settings file)")
    assert _warning_lines(capsys.readouterr().err) == [expected]


def test_a_name_for_another_unit_is_still_refused(tmp_path):
    path = _write(tmp_path / "log.csv", np.arange(100) * 25.0, "t_ms")
    with pytest.raises(InputError, match=r"named for ms but time is read in s; pass "
                                         r"--time-unit ms"):
        read_recording(path, options=ReadOptions(columns={"time": "t_ms"}))


def test_the_warning_names_the_files_column(tmp_path):
    where = _Where("run.mat", names=(("time", "stamp"),))
    text = time_step_warning(np.arange(10) * 40.0, ReadOptions(columns={"time": "stamp"}),
                             where)
    assert text.startswith("run.mat: column 'stamp' (time): one sample every 40 s (0.025 Hz)")
    assert "--time-unit ms" in text


def test_fit_and_hk_read_say_it(tmp_path, capsys):
    rec = simulate_experiment("noise", seed=1)
    path = tmp_path / "ms.csv"
    rec_ms = rec.to_frame().assign(time=np.round(rec.time * 1e3, 6))
    rec_ms.to_csv(path, index=False)
    capsys.readouterr()
    hk.read(path)
    assert len(_warning_lines(capsys.readouterr().err)) == 1
    code = main(["fit", str(path), "--cells", "1", "--no-band", "--out",
                 str(tmp_path / "m.json")])
    captured = capsys.readouterr()
    assert code in (0, 3)  # the fit runs on the numbers as read; the line says why they are odd
    expected = (f"hystkit: warning: {path}: column 'time': one sample every 25 s (0.04 Hz) "
                "read in s; if the time is in ms, pass --time-unit ms (or time_unit = \"ms\" "
                "in the settings file)")
    assert _warning_lines(captured.err) == [expected]
    assert "samples at 0.04 Hz" in captured.out
