"""``hystkit batch`` model files remember how their fit recordings were read, as ``hystkit fit``
does (issue 27, item 3): a fleet in a lab's layout (``t_ms``, ``x_mm``, ``R_ohm``, time in ms,
a units line) fitted with ``--columns``/``--time-unit``/``--units-row``, and each sensor's
model then used by ``hystkit evaluate`` on a file of that layout without any option.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from hystkit.batch import SensorJob, fit_sensor
from hystkit.compensation import load_compensator
from hystkit.io import ReadOptions

from ..cli_support import LAB_COLUMNS as COLUMNS
from ..cli_support import LAB_SAID as SAID
from ..cli_support import run_cli
from ..cli_support import write_lab_csv as _write_lab_csv

OWN = ["--columns", "time=t_ms,position=x_mm,sensor=R_ohm", "--time-unit", "ms",
       "--units-row"]
UNITS = (("position", "mm"), ("sensor", "Ohm"))


@pytest.fixture(scope="module")
def fleet(tmp_path_factory) -> Path:
    """Two sensors in the lab's layout (a fit and a validation run each) and manifest.csv."""
    folder = tmp_path_factory.mktemp("lab_fleet")
    lines = ["sensor,fit,validate,size"]
    for k in range(2):
        _write_lab_csv(folder / f"s{k}_fit.csv", 10 + k)
        _write_lab_csv(folder / f"s{k}_val.csv", 20 + k)
        lines.append(f"s{k},s{k}_fit.csv,s{k}_val.csv,1")
    (folder / "manifest.csv").write_text("\n".join(lines) + "\n")
    return folder


def test_batch_models_are_read_back_without_options(fleet, tmp_path, capsys):
    out = tmp_path / "out"
    code, stdout, err = run_cli(capsys, "batch", fleet / "manifest.csv", "--out", out, *OWN)
    assert code == 0, stdout + err
    for k in range(2):
        comp = load_compensator(out / "models" / f"s{k}.json")
        assert comp.reading == ReadOptions(columns=COLUMNS, time_unit="ms", units_row=True,
                                           units=UNITS)
        assert comp.fit_info["units"] == dict(UNITS)
        scores = tmp_path / f"s{k}.json"
        code, stdout, err = run_cli(capsys, "evaluate", out / "models" / f"s{k}.json",
                                    fleet / f"s{k}_val.csv", "--json", scores)
        assert code == 0, err
        assert f"reading {fleet / f's{k}_val.csv'} {SAID}" in stdout.splitlines()
        # the batch's own score of the same validation run, read the same way
        record = json.loads((out / "sensors" / f"s{k}.json").read_text())
        assert json.loads(scores.read_text())["r2"] == record["scores"][0]["r2"]


def test_without_the_options_the_lab_file_is_refused(fleet, tmp_path, capsys):
    """The other direction: an older batch model (no reading) needs the options again."""
    out = tmp_path / "out"
    assert run_cli(capsys, "batch", fleet / "manifest.csv", "--out", out, *OWN)[0] == 0
    model = out / "models" / "s0.json"
    data = json.loads(model.read_text())
    del data["reading"]
    old = tmp_path / "old.json"
    old.write_text(json.dumps(data), encoding="utf-8")
    code, _, err = run_cli(capsys, "evaluate", old, fleet / "s0_val.csv")
    assert code == 2 and "missing required column 'time'" in err


def test_a_split_recording_keeps_its_units_and_reading(fleet):
    """A recording fitted on its first half (the folder convention) remembers the same."""
    job = SensorJob("lone", fit=(fleet / "s0_fit.csv",), size=1, split=True)
    options = ReadOptions(columns=COLUMNS, time_unit="ms", units_row=True)
    result = fit_sensor(job, read_options=options)
    assert result["row"]["status"] != "failed", result["row"]["error"]
    comp = result["compensator"]
    assert comp.reading == ReadOptions(columns=COLUMNS, time_unit="ms", units_row=True,
                                       units=UNITS)
    assert comp.fit_info["units"] == dict(UNITS)


def test_fit_files_read_differently_are_not_remembered(fleet, tmp_path):
    std = tmp_path / "std.csv"
    frame = pd.read_csv(fleet / "s1_fit.csv", skiprows=[1])
    pd.DataFrame({"time": frame["t_ms"] / 1e3, "position": frame["x_mm"],
                  "sensor": frame["R_ohm"]}).to_csv(std, index=False)
    lab = ReadOptions(columns=COLUMNS, time_unit="ms", units_row=True)
    job = SensorJob("mixed", fit=(fleet / "s0_fit.csv", std), validate=(fleet / "s0_val.csv",),
                    size=1)
    reading = {str(fleet / "s0_fit.csv"): lab, str(std): ReadOptions(),
               str(fleet / "s0_val.csv"): lab}
    result = fit_sensor(job, read_options=reading)
    assert result["row"]["status"] != "failed", result["row"]["error"]
    assert result["compensator"].reading is None
