"""The options records of settling, simulate-settling, datasets, creep, table, pl-search and
export (issue 28.4): a command line parses into one frozen record and leaves the namespace as
argparse made it; the command runs from the record alone, with the same checks first."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from hystkit.cli import (
    cmd_creep,
    cmd_datasets,
    cmd_export,
    cmd_pl_search,
    cmd_settling,
    cmd_table,
)
from hystkit.cli._main import _parser
from hystkit.cli._many_models import ParallelOptions
from hystkit.cli._reading import Reader
from hystkit.errors import HystkitError

# command line, its run function, its record, the fields expected in the record
CASES = [
    (["settling", "log.csv", "--out", "s", "--traces", "r1,r2", "--time-unit", "min",
      "--model", "drop", "--threshold", "0.5", "--force"],
     "cmd_settling:run_settling", cmd_settling.SettlingOptions,
     {"log": Path("log.csv"), "out": Path("s"), "time_column": None, "time_unit": "min",
      "traces": ("r1", "r2"), "model": "drop", "threshold": 0.5, "force": True}),
    (["simulate-settling", "--out", "log.csv", "--hours", "2", "--interval", "5"],
     "cmd_settling:run_simulate_settling", cmd_settling.SimulateSettlingOptions,
     {"out": Path("log.csv"), "hours": 2.0, "interval": 5.0, "seed": 0, "force": False}),
    (["datasets", "list", "piezo_actuator", "--root", "data"],
     "cmd_datasets:run_list", cmd_datasets.DatasetsOptions,
     {"name": "piezo_actuator", "root": Path("data")}),
    (["datasets", "show", "mr_damper"], "cmd_datasets:run_show", cmd_datasets.DatasetsOptions,
     {"name": "mr_damper", "root": None}),
    # --force before the subcommand counts (the child's default does not reset it)
    (["datasets", "--force", "export", "bh_loops", "--excerpt", "--role", "forward",
      "--segment", "a", "--out", "x.mat"],
     "cmd_datasets:run_export", cmd_datasets.DatasetsExportOptions,
     {"name": "bh_loops", "variant": None, "segment": "a", "role": "forward", "excerpt": True,
      "root": None, "out": Path("x.mat"), "force": True}),
    (["creep", "--quick", "--models", "mpl,pi", "--size", "mpl=2", "--size", "pi=9",
      "--seed", "7", "--out", "c"],
     "cmd_creep:run_creep", cmd_creep.CreepOptions,
     {"hours": 1.0, "amplitude": 2.0, "models": "mpl,pi", "sizes": ("mpl=2", "pi=9"),
      "seed": 7, "quick": True, "out": Path("c"), "force": False}),
    (["table", "--force", "5.4", "--size", "2", "--scope-rate", "5e4"],
     "cmd_table:run_table_5_4", cmd_table.Table54Options,
     {"model": "mpl", "size": 2, "fit_seed": 1, "val_seed": 2, "scope_rate": 5e4,
      "quick": False, "out": None, "force": True}),
    (["table", "2.2", "--excitation", "sine", "--repeats", "4", "--size", "pl=3"],
     "cmd_table:run_table_2_2", cmd_table.Table22Options,
     {"repeats": 4, "seed": 1, "excitation": "sine", "models": None, "sizes": ("pl=3",),
      "quick": False, "force": False}),
    (["pl-search", "d.csv", "--n", "1,2", "--s", "0", "--direction", "sensor-to-position",
      "--workers", "1", "--sep", ";", "--json", "r.json"],
     "cmd_pl_search:run_pl_search", cmd_pl_search.PlSearchOptions,
     {"data": Path("d.csv"), "n": (1, 2), "p": (5.0, 21.0), "m": (1, 5), "s": (0.0,),
      "direction": "sensor-to-position", "json": Path("r.json"), "force": False,
      "parallel": ParallelOptions(1, None, None)}),
    (["export", "m.json", "--lang", "matlab", "--name", "comp", "--level", "0.8", "--out", "e"],
     "cmd_export:run_export", cmd_export.ExportOptions,
     {"model": Path("m.json"), "lang": "matlab", "out": Path("e"), "double": False,
      "name": "comp", "level": 0.8, "force": False}),
]


@pytest.mark.parametrize(("argv", "run", "record", "expected"), CASES,
                         ids=[" ".join(c[0][:2]) for c in CASES])
def test_command_line_parses_into_its_frozen_record(argv, run, record, expected):
    args = _parser(argv[0]).parse_args(argv)
    assert args.run == run
    parsed = dict(vars(args))
    opts = record.from_args(args)
    assert vars(args) == parsed  # nothing is written onto the namespace
    assert {name: getattr(opts, name) for name in expected} == expected
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(opts, next(iter(expected)), None)


def test_pl_search_reads_with_the_command_lines_reading_options():
    args = _parser("pl-search").parse_args(["pl-search", "d.csv", "--sep", ";"])
    assert cmd_pl_search.PlSearchOptions.from_args(args).reader.given == {"sep": ";"}
    args = _parser("pl-search").parse_args(["pl-search", "d.csv"])
    assert cmd_pl_search.PlSearchOptions.from_args(args).reader.given == {}


def test_settling_runs_from_its_records(tmp_path, capsys):
    log = tmp_path / "log.csv"
    assert cmd_settling.simulate_settling(
        cmd_settling.SimulateSettlingOptions(log, 24.0, 10.0, 0, False)) == 0
    out = tmp_path / "settling"
    opts = cmd_settling.SettlingOptions(log, out, None, "h", ("r1",), "drop", 0.1, False)
    assert cmd_settling.settling(opts) == 0
    report = json.loads((out / "settling.json").read_text())
    assert (report["model"], list(report["traces"])) == ("drop", ["r1"])
    assert report["traces"]["r1"]["fit"]["model"] == "drop"
    # an existing output is refused before the log is read (nothing overwritten)
    with pytest.raises(HystkitError, match="already exists; pass --force"):
        cmd_settling.settling(dataclasses.replace(opts, log=tmp_path / "missing.csv"))
    with pytest.raises(HystkitError, match="missing.csv: file not found"):
        cmd_settling.settling(dataclasses.replace(opts, log=tmp_path / "missing.csv",
                                                  force=True))
    assert "r1: drop" in capsys.readouterr().out


def test_datasets_export_runs_from_its_record(tmp_path, capsys):
    out = tmp_path / "piezo.csv"
    opts = cmd_datasets.DatasetsExportOptions("piezo_micromanipulator", None, None, "forward",
                                              True, None, out, False)
    assert cmd_datasets.export_dataset(opts) == 0
    meta = json.loads((tmp_path / "piezo.csv.json").read_text())
    assert (meta["role"], meta["excerpt"]) == ("forward", True)
    with pytest.raises(HystkitError, match="already exists; pass --force"):
        cmd_datasets.export_dataset(opts)
    assert f"wrote {out}" in capsys.readouterr().out


def test_option_checks_come_before_any_work(tmp_path):
    """The records carry the options as given; the checks run first, in the command."""
    with pytest.raises(HystkitError, match="--model boucwen: table 5.4 compensates"):
        cmd_table.table_5_4(cmd_table.Table54Options("boucwen", None, 1, 2, 2e4, True,
                                                     None, False))
    with pytest.raises(HystkitError, match="unknown model"):
        cmd_table.table_2_2(cmd_table.Table22Options(3, 1, "noise", "nope", (), True, None,
                                                     False))
    with pytest.raises(HystkitError, match="--size expects MODEL=N"):
        cmd_creep.creep(cmd_creep.CreepOptions(1.0, 2.0, None, ("mpl=0",), 3, True, None,
                                               False))
    data = tmp_path / "d.csv"
    data.write_text("time,position,sensor\n0,0,0\n")
    search = cmd_pl_search.PlSearchOptions(data, (1,), (21.0,), (1,), (0.001,),
                                           "position-to-sensor", data, False,
                                           ParallelOptions(1, None, None),
                                           Reader({}))
    with pytest.raises(HystkitError, match="also an input of this command"):
        cmd_pl_search.pl_search(search)
