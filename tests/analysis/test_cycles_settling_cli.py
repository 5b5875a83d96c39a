"""``hystkit cycles`` and ``hystkit settling`` from the command line, on the virtual sensor."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_allclose

from hystkit.analysis import cycle_table
from hystkit.cli._main import main
from hystkit.preprocess import gauge_symmetry, relative_change


@pytest.fixture(scope="module")
def raw_run(tmp_path_factory):
    """8 s of the raw sine (3 complete cycles) at 100 kHz and its preprocessed recording."""
    folder = tmp_path_factory.mktemp("raw")
    raw, pre = folder / "raw.csv", folder / "pre.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--raw", "--duration", "8",
                 "--scope-rate", "1e5", "--out", str(raw)]) == 0
    assert main(["preprocess", str(raw), "--out", str(pre)]) == 0
    return raw, pre


def _error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hystkit: error: "), err
    return err[0]


def test_cycles_on_raw_equals_cycles_on_its_preprocessed_recording(raw_run, tmp_path):
    raw, pre = raw_run
    assert main(["cycles", str(raw), "--raw", "--out", str(tmp_path / "a")]) == 0
    assert main(["cycles", str(pre), "--out", str(tmp_path / "b"), "--cycles", "1,3"]) == 0
    a = json.loads((tmp_path / "a" / "cycles.json").read_text())
    b = json.loads((tmp_path / "b" / "cycles.json").read_text())
    assert a["n_cycles"] == b["n_cycles"] == 3
    assert a["signals"] == b["signals"]
    assert b["cycles_drawn"] == [1, 3]
    for name in ("cycles.csv", "cycles.png", "cycles.svg"):
        assert (tmp_path / "a" / name).stat().st_size > 0


def test_cycles_numbers_are_the_library_numbers_on_the_gauge_columns(raw_run, tmp_path):
    _, pre = raw_run
    assert main(["cycles", str(pre), "--out", str(tmp_path / "c")]) == 0
    data = pd.read_csv(pre)
    dr1, dr2 = relative_change(data["r1"].to_numpy()), relative_change(data["r2"].to_numpy())
    table = cycle_table(data["time"], data["position"], {"d": dr1 - dr2})
    rows = pd.read_csv(tmp_path / "c" / "cycles.csv")
    diff = rows[rows["signal"] == "dR1/R1 - dR2/R2"]
    assert_allclose(diff["area"], table.area["d"], rtol=1e-12)
    assert_allclose(diff["offset"], table.offset["d"], rtol=1e-12)
    report = json.loads((tmp_path / "c" / "cycles.json").read_text())
    assert_allclose(report["signals"]["dR1/R1 - dR2/R2"]["drift_per_hour"],
                    table.drift["d"].per_hour, rtol=1e-12)
    # table 3.1's column, from the mean gauge resistances
    assert_allclose(report["gauges"]["symmetry_pct"],
                    100 * gauge_symmetry(data["r1"].to_numpy(), data["r2"].to_numpy()))


def test_table_3_1_symmetry_column_follows_from_its_resistances():
    """The document's last column is 2 (R1 - R2) / (R1 + R2) of its own R columns (to 1 %)."""
    from hystkit.cli.cmd_cycles import TABLE_3_1

    for r1, r2, pct in TABLE_3_1.values():
        assert abs(100 * gauge_symmetry(r1, r2) - pct) < 1.0


def test_cycles_without_gauge_columns_analyses_the_sensor(tmp_path, capsys):
    rec = tmp_path / "sine.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(rec)]) == 0
    assert main(["cycles", str(rec), "--out", str(tmp_path / "o")]) == 0
    report = json.loads((tmp_path / "o" / "cycles.json").read_text())
    assert list(report["signals"]) == ["sensor"] and report["gauges"] is None
    assert report["n_cycles"] == 99


def test_outputs_are_not_overwritten_without_force(raw_run, tmp_path, capsys):
    _, pre = raw_run
    out = tmp_path / "o"
    assert main(["cycles", str(pre), "--out", str(out)]) == 0
    before = (out / "cycles.json").read_bytes()
    capsys.readouterr()
    assert main(["cycles", str(pre), "--out", str(out), "--cycles", "2"]) == 2
    assert "already exists" in _error_line(capsys)
    assert (out / "cycles.json").read_bytes() == before
    assert main(["cycles", str(pre), "--out", str(out), "--cycles", "2", "--force"]) == 0
    assert json.loads((out / "cycles.json").read_text())["cycles_drawn"] == [2]


@pytest.mark.parametrize(("args", "expected"), [
    (["--cycles", "7"], "asks for cycle 7, but the recording has 3 complete cycle(s)"),
    (["--cycles", "0,2"], "expected 'all' or cycle numbers"),
    (["--raw"], "--raw needs the settings file"),
])
def test_bad_cycles_input_is_one_line(raw_run, tmp_path, capsys, args, expected):
    _, pre = raw_run
    assert main(["cycles", str(pre), "--out", str(tmp_path / "o"), *args]) == 2
    assert expected in _error_line(capsys)
    assert not (tmp_path / "o").exists()


def test_a_recording_without_a_full_cycle_is_one_line(tmp_path, capsys):
    rec = tmp_path / "short.csv"
    t = np.arange(40) / 40
    pd.DataFrame({"time": t, "position": np.sin(t), "sensor": t}).to_csv(rec, index=False)
    assert main(["cycles", str(rec), "--out", str(tmp_path / "o")]) == 2
    assert "no complete cycle" in _error_line(capsys)


def test_settling_from_the_command_line(tmp_path, capsys):
    log, out = tmp_path / "log.csv", tmp_path / "s"
    assert main(["simulate-settling", "--out", str(log), "--interval", "15"]) == 0
    assert main(["settling", str(log), "--out", str(out)]) == 0
    report = json.loads((out / "settling.json").read_text())
    block = report["traces"]["block"]
    assert block["fit"]["model"] == "rise-drop"
    tau = block["fit"]["params"]["tau_drop_h"]
    assert abs(tau - 15.0) < 3 * block["fit"]["stderr"]["tau_drop_h"]
    assert report["traces"]["block_annealed"]["fit"]["model"] == "drop"
    # the gauges of the virtual sensor settle with its own 10 h time constant
    r1 = report["traces"]["r1"]["fit"]
    assert abs(r1["params"]["tau_drop_h"] - 10.0) < 3 * r1["stderr"]["tau_drop_h"]
    assert 48 < block["rest_time"]["hours"] < 72
    assert (out / "settling.png").stat().st_size > 0


def test_a_bad_log_cell_is_named_by_column_and_row(tmp_path, capsys):
    log = tmp_path / "log.csv"
    log.write_text("time_h,r\n0,10\n1,9\n2,abc\n")
    assert main(["settling", str(log), "--out", str(tmp_path / "s")]) == 2
    line = _error_line(capsys)
    assert "column 'r' row 4" in line and "'abc'" in line


def test_a_missing_trace_column_is_one_line(tmp_path, capsys):
    log = tmp_path / "log.csv"
    log.write_text("time_h,r\n0,10\n1,9\n")
    assert main(["settling", str(log), "--out", str(tmp_path / "s"), "--traces", "x"]) == 2
    assert "no column 'x'" in _error_line(capsys)


def test_a_trace_that_cannot_be_fitted_is_reported_and_the_others_written(tmp_path, capsys):
    t = np.linspace(0, 48, 200)
    log = tmp_path / "log.csv"
    pd.DataFrame({"time_h": t, "good": 1e3 + 500 * np.exp(-t / 8),
                  "rising": 1e3 + 10 * t}).to_csv(log, index=False)
    assert main(["settling", str(log), "--out", str(tmp_path / "s")]) == 3
    captured = capsys.readouterr()
    assert "rising: NOT FITTED" in captured.out
    assert "1 trace(s) failed: rising" in captured.err
    report = json.loads((tmp_path / "s" / "settling.json").read_text())
    assert report["traces"]["rising"]["fitted"] is False
    assert_allclose(report["traces"]["good"]["fit"]["params"]["tau_drop_h"], 8.0, rtol=1e-6)


@pytest.mark.parametrize("command", ["cycles", "settling", "simulate-settling"])
def test_every_option_has_help(command):
    import argparse

    from hystkit.cli._main import _parser

    action = next(a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction))
    sub = action.choices[command]
    sub.format_help()
    missing = [a.dest for a in sub._actions if not isinstance(a, argparse._HelpAction)
               and not str(a.help or "").strip()]
    assert missing == []


def test_raw_settings_without_the_bridge_and_reading_options_with_raw_are_one_line(
        raw_run, tmp_path, capsys):
    raw, _ = raw_run
    linked = tmp_path / "nobridge.csv"
    linked.symlink_to(raw)
    (tmp_path / "nobridge.toml").write_text("v_supply = 2.0\n")
    assert main(["cycles", str(linked), "--raw", "--out", str(tmp_path / "o")]) == 2
    assert "r_bridge not set" in _error_line(capsys)
    assert main(["cycles", str(raw), "--raw", "--time-unit", "ms",
                 "--out", str(tmp_path / "o")]) == 2
    assert "do not apply" in _error_line(capsys)
    assert not (tmp_path / "o").exists()


def test_cycles_all_draws_every_complete_cycle(raw_run, tmp_path):
    _, pre = raw_run
    assert main(["cycles", str(pre), "--cycles", "all", "--out", str(tmp_path / "o")]) == 0
    assert json.loads((tmp_path / "o" / "cycles.json").read_text())["cycles_drawn"] == [1, 2, 3]


def test_a_collapsed_settling_fit_exits_3_and_is_not_fitted_in_json(tmp_path, capsys):
    """Review 14, sec. 2: the drop law on the printed block was reported as a fit, exit 0."""
    log, out = tmp_path / "settle.csv", tmp_path / "st"
    assert main(["simulate-settling", "--out", str(log), "--hours", "24"]) == 0
    assert main(["settling", str(log), "--out", str(out), "--model", "drop",
                 "--traces", "block"]) == 3
    printed = capsys.readouterr().out
    assert "block: NOT FITTED: drop: collapsed: r_final" in printed
    block = json.loads((out / "settling.json").read_text())["traces"]["block"]
    assert block["fitted"] is False and "r_final ended at its lower bound" in block["reason"]


def test_a_time_unit_that_contradicts_the_column_suffix_is_one_warning(tmp_path, capsys):
    log = tmp_path / "settle.csv"
    assert main(["simulate-settling", "--out", str(log), "--hours", "24",
                 "--interval", "30"]) == 0
    capsys.readouterr()
    assert main(["settling", str(log), "--out", str(tmp_path / "d"), "--time-unit", "d",
                 "--traces", "block_annealed"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith("hystkit: warning: column 'time_h' looks like 'h' but --time-unit "
                             "is 'd'")
    assert main(["settling", str(log), "--out", str(tmp_path / "h"),
                 "--traces", "block_annealed"]) == 0
    assert capsys.readouterr().err == ""
