"""``hk.fit`` given file paths remembers how they were read, as ``hystkit fit`` does (issue 27,
item 3): a lab's CSV (``t_ms``, ``x_mm``, ``R_ohm``, time in ms, a units line) read through its
settings file is fitted in Python, and ``hystkit evaluate`` reads a file of the same layout
without any option.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import hystkit as hk
from hystkit.errors import InputError
from hystkit.io import ReadOptions, Recording

from .cli_support import LAB_COLUMNS as COLUMNS
from .cli_support import LAB_SAID as SAID
from .cli_support import run_cli
from .cli_support import write_lab_csv as _write_lab_csv

SETTINGS = ('time_unit = "ms"\nunits_row = true\n\n'
            '[columns]\ntime = "t_ms"\nposition = "x_mm"\nsensor = "R_ohm"\n')


@pytest.fixture(scope="module")
def lab(tmp_path_factory) -> dict[str, Path]:
    """train.csv with its settings file (train.toml), val.csv of the same layout without one,
    and a model fitted by hk.fit on train.csv saved to model.json."""
    folder = tmp_path_factory.mktemp("api_reading")
    _write_lab_csv(folder / "train.csv", 1)
    _write_lab_csv(folder / "val.csv", 2)
    (folder / "train.toml").write_text(SETTINGS, encoding="utf-8")
    comp = hk.fit(folder / "train.csv", "mpl", size=1, band=False)
    hk.save(comp, folder / "model.json")
    return {"train": folder / "train.csv", "val": folder / "val.csv",
            "model": folder / "model.json"}


def test_hk_fit_of_a_file_remembers_how_it_was_read(lab):
    comp = hk.load(lab["model"])
    assert comp.reading == ReadOptions(columns=COLUMNS, time_unit="ms", units_row=True,
                                       units=(("position", "mm"), ("sensor", "Ohm")))
    assert comp.fit_info["units"] == {"position": "mm", "sensor": "Ohm"}
    stored = json.loads(lab["model"].read_text())["reading"]
    assert stored["columns"] == dict(COLUMNS) and stored["time_unit"] == "ms"


def test_evaluate_reads_the_same_layout_without_options(lab, tmp_path, capsys):
    remembered, given = tmp_path / "remembered.json", tmp_path / "given.json"
    code, stdout, err = run_cli(capsys, "evaluate", lab["model"], lab["val"], "--json",
                                remembered)
    assert code == 0, err
    assert f"reading {lab['val']} {SAID}" in stdout.splitlines()
    # the same scores as with the options given on the command line
    code, stdout, err = run_cli(capsys, "evaluate", lab["model"], lab["val"], "--columns",
                                "time=t_ms,position=x_mm,sensor=R_ohm", "--time-unit", "ms",
                                "--units-row", "--json", given)
    assert code == 0, err
    scores = [json.loads(p.read_text()) for p in (remembered, given)]
    for key in ("r2", "e_rms_pct", "n_samples"):
        assert scores[0][key] == scores[1][key], key
    assert scores[0]["n_samples"] == 2400  # the units line is not a sample


def test_a_model_fitted_on_memory_remembers_nothing(lab, tmp_path, capsys):
    """The other direction: fitted on a Recording, the lab's file needs its options."""
    rec = hk.read(lab["train"])  # with train.toml
    comp = hk.fit(rec, "mpl", size=1, band=False)
    assert comp.reading is None
    assert comp.fit_info["units"] == {"position": "mm", "sensor": "Ohm"}
    hk.save(comp, tmp_path / "memory.json")
    code, _, err = run_cli(capsys, "evaluate", tmp_path / "memory.json", lab["val"])
    assert code == 2 and "missing required column 'time'" in err


def test_files_read_differently_are_not_remembered_and_said(lab, tmp_path, capsys):
    std = tmp_path / "std.csv"
    hk.read(lab["val"], columns=dict(COLUMNS), time_unit="ms", units_row=True).to_frame() \
        .to_csv(std, index=False)  # hystkit's own names, seconds
    capsys.readouterr()
    comp = hk.fit([lab["train"], std], "mpl", size=1, band=False)
    assert comp.reading is None
    err = capsys.readouterr().err
    assert "hystkit: note: the training files were read differently" in err
    assert f"{std}: columns time,position,sensor, time in s" in err


def test_recordings_in_different_units_are_refused(lab):
    rec = hk.read(lab["train"])  # position in mm (its units line)
    um = Recording(time=rec.time, sensor=rec.sensor, position=rec.position * 1e3,
                   source="val_um", units={"position": "um", "sensor": "Ohm"})
    with pytest.raises(InputError,
                       match="val_um: position is in 'um', an earlier recording's in 'mm'"):
        hk.fit([rec, um], "mpl", size=1, band=False)
