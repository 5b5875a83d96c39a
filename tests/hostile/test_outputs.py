"""Hostile output paths: refused on one line before any work; nothing written or overwritten.

Every case runs in-process in a scratch folder with copies of the valid inputs and asserts
exit 2 (never the internal-error code 70), one ``hystkit: error:`` line naming the output,
no traceback, and the folder exactly as it was (no file changed, nothing new, no temporary).
"""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from hystkit.cli import cmd_core

from .conftest import Run, entries, snapshot

# argv ({name} = an input copied into the scratch folder), fragments the error line must hold
CASES = {
    "compensate-into-proc": ("compensate model.json val.csv --out /proc/x.csv",
                             ["/proc/x.csv", "cannot write"]),
    "compensate-parent-is-a-file": ("compensate model.json val.csv --out fit.csv/x.csv",
                                    ["fit.csv/x.csv", "is a file"]),
    "compensate-over-its-input": ("compensate model.json val.csv --out val.csv --force",
                                  ["val.csv", "input"]),
    "compensate-over-the-model": ("compensate model.json val.csv --out model.json --force",
                                  ["model.json", "input"]),
    "compensate-existing-no-force": ("compensate model.json val.csv --out taken.csv",
                                     ["taken.csv", "--force"]),
    "compensate-out-is-a-folder": ("compensate model.json val.csv --out sub --force",
                                   ["sub", "folder"]),
    "compensate-bad-suffix": ("compensate model.json val.csv --out x.txt", ["x.txt", ".txt"]),
    "evaluate-json-into-proc": ("evaluate model.json val.csv --json /proc/x.json",
                                ["/proc/x.json"]),
    "evaluate-json-over-data": ("evaluate model.json val.csv --json val.csv --force",
                                ["val.csv", "input"]),
    "fit-into-proc": ("fit fit.csv --model mpl --out /proc/m.json", ["/proc/m.json"]),
    "fit-over-its-data": ("fit fit.csv val.csv --model mpl --out val.csv --force",
                          ["val.csv", "input"]),
    "fit-deep-under-a-file": ("fit fit.csv --model mpl --out fit.csv/a/b/m.json",
                              ["fit.csv", "is a file"]),
    "simulate-into-proc": ("simulate-sensor --excitation sine --out /proc/s.csv",
                           ["/proc/s.csv"]),
    "simulate-raw-into-proc": ("simulate-sensor --excitation sine --raw --out /proc/s.csv",
                               ["/proc/s.csv"]),
    "demo-into-proc": ("demo --out /proc/d", ["/proc/d"]),
    "demo-out-is-a-file": ("demo --out taken.csv --force", ["taken.csv", "is a file"]),
    "demo-existing-files-no-force": ("demo --out report", ["report/metrics.json", "--force"]),
    "control-into-proc": ("control --scheme direct --bode --out /proc/c", ["/proc/c"]),
    "control-under-a-file": ("control --scheme direct --bode --out fit.csv/c",
                             ["fit.csv", "is a file"]),
    "compare-out-is-a-file": ("compare fit.csv val.csv --out taken.csv", ["taken.csv",
                                                                         "is a file"]),
    "generalize-existing-no-force": ("generalize fit.csv val.csv --out report",
                                     ["report/generalize.json", "--force"]),
    "select-report-into-proc": ("select fit.csv --out m.json --report /proc/r", ["/proc/r"]),
    "select-over-its-data": ("select fit.csv --out fit.csv --force", ["fit.csv", "input"]),
    "preprocess-report-is-out": ("preprocess fit.csv --out p.csv --report p.csv",
                                 ["p.csv", "data output"]),
    "preprocess-into-proc": ("preprocess fit.csv --out /proc/p.csv", ["/proc/p.csv"]),
    "preprocess-over-raw": ("preprocess fit.csv --out fit.csv --force", ["fit.csv", "input"]),
    "pl-search-json-into-proc": ("pl-search fit.csv --json /proc/x.json", ["/proc/x.json"]),
    "stability-json-over-model": ("stability model.json --json model.json --force",
                                  ["model.json", "input"]),
    "compensate-over-dev-null": ("compensate model.json val.csv --out /dev/null --force",
                                 ["/dev/null", "not a regular file"]),
    "compensate-name-too-long": (f"compensate model.json val.csv --out {'a' * 250}.csv",
                                 ["file name too long"]),
    "demo-folder-name-too-long": (f"demo --out {'d' * 250}", ["file name too long"]),
    "datasets-export-into-proc": ("datasets export mr_damper --excerpt --out /proc/x.csv",
                                  ["/proc/x.csv"]),
}


@pytest.fixture
def scratch(good: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Copies of the valid inputs, an existing output ``taken.csv``, a folder ``sub`` and a
    ``report`` folder holding every demo and generalize file name."""
    for key in ("fit", "val", "model"):
        shutil.copy(good[key], tmp_path / good[key].name)
        os.chmod(tmp_path / good[key].name, 0o644)
    (tmp_path / "taken.csv").write_text("someone's results\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "report").mkdir()
    for name in ("metrics.json", "generalize.json"):
        (tmp_path / "report" / name).write_text("{}\n")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _refused(cli: Callable[..., Run], folder: Path, argv: list[str],
             fragments: list[str]) -> tuple[Run, float]:
    before, names = snapshot(folder), entries(folder)
    t0 = time.perf_counter()
    run = cli(*argv)
    assert run.code == 2, f"exit {run.code}: {run.err}"
    run.error_line(*fragments)
    assert snapshot(folder) == before and entries(folder) == names
    return run, time.perf_counter() - t0


@pytest.mark.parametrize("case", CASES)
def test_bad_output_is_refused_before_any_work(case: str, scratch: Path,
                                               cli: Callable[..., Run]) -> None:
    template, fragments = CASES[case]
    _, seconds = _refused(cli, scratch, template.split(), fragments)
    assert seconds < 5, "refused only after doing the work"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_is_refused(scratch: Path, cli: Callable[..., Run]) -> None:
    locked = scratch / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        _refused(cli, scratch, ["compensate", "model.json", "val.csv", "--out",
                                "locked/x.csv"], ["locked", "permission denied"])
    finally:
        locked.chmod(0o755)


def test_non_finite_scores_never_reach_json(scratch: Path, cli: Callable[..., Run],
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """A NaN score (constructed: evaluate patched) is refused by the writer, key named."""
    real = cmd_core.evaluate

    def nan_r2(*args: object, **kwargs: object) -> dict:
        return {**real(*args, **kwargs), "r2": float("nan")}

    monkeypatch.setattr(cmd_core, "evaluate", nan_r2)
    _refused(cli, scratch, ["evaluate", "model.json", "val.csv", "--json", "e.json"],
             ["e.json", "r2 is nan"])


def test_non_finite_estimates_never_reach_a_recording(scratch: Path, cli: Callable[..., Run],
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """An inf estimate (constructed: load_compensator patched) is refused, column and row
    named, even past the compensator's own checks."""
    real = cmd_core.load_compensator

    def infinite(path: Path):
        comp = real(path)

        class Wrapped:
            def __getattr__(self, name: str):
                return getattr(comp, name)

            def estimate(self, rec, **kwargs):
                y = np.array(comp.estimate(rec, **kwargs))
                y[41] = np.inf
                return y

        return Wrapped()

    monkeypatch.setattr(cmd_core, "load_compensator", infinite)
    monkeypatch.setattr(cmd_core, "use_flags", lambda comp, rec, est: {
        "sensor_outside": None, "estimate_outside": None})
    _refused(cli, scratch, ["compensate", "model.json", "val.csv", "--out", "c.csv"],
             ["c.csv", "position_estimate", "row 42"])
