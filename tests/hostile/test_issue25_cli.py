"""Issue 25.10: outputs that cannot be written and inputs that are not what an option says.

A closed stdout, a full disk under ``stream``, a 300-character output name, ``--units-row`` on
a file without a units line, ``stream``'s unterminated last line, ``report --out r.txt``,
``--mat-var`` on a CSV and a settings file with a UTF-8 byte-order mark: each is one clear
error line (exit 2, nothing written) or, for the BOM, read as it is meant.
"""

from __future__ import annotations

import codecs
import io
import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pandas as pd
import pytest

from .conftest import Run, entries, snapshot


@pytest.fixture
def scratch(good: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Writable copies of the valid inputs, the working folder."""
    for key in ("fit", "val", "model", "val_parquet"):
        shutil.copy(good[key], tmp_path / good[key].name)
        os.chmod(tmp_path / good[key].name, 0o644)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _refused(cli: Callable[..., Run], folder: Path, argv: list[object],
             *fragments: object) -> Run:
    """Exit 2, one error line holding every fragment, the folder as it was."""
    before, names = snapshot(folder), entries(folder)
    run = cli(*argv)
    assert run.code == 2, f"exit {run.code}: {run.err}"
    run.error_line(*fragments)
    assert snapshot(folder) == before and entries(folder) == names
    return run


def _shell(command: str, cwd: Path) -> subprocess.CompletedProcess:
    """``python -m hystkit COMMAND`` through a shell (for ``>&-``: fd 1 closed at start)."""
    return subprocess.run(f"{sys.executable} -m hystkit {command}", shell=True, cwd=cwd,
                          capture_output=False, stderr=subprocess.PIPE, text=True,
                          timeout=300, check=False,
                          env={**os.environ, "MPLBACKEND": "Agg"})


# --------------------------------------------------------------------------- closed stdout


def test_closed_stdout_is_no_traceback_in_the_program(tmp_path: Path) -> None:
    """The regression: the program's last flush of a closed (None) stdout raised."""
    listing = _shell("datasets list >&-", tmp_path)
    assert "Traceback" not in listing.stderr, listing.stderr
    assert listing.returncode == 2
    assert listing.stderr.strip() == ("hystkit: error: standard output is closed: nowhere to "
                                      "write the list (redirect it to a file or a pipe)")
    # a command whose product is a file still makes it; its progress lines go nowhere
    simulated = _shell("simulate-sensor --excitation sine --out s.csv >&-", tmp_path)
    assert "Traceback" not in simulated.stderr, simulated.stderr
    assert simulated.returncode == 0 and (tmp_path / "s.csv").stat().st_size > 10_000


def test_stream_to_a_closed_stdout_is_refused_before_any_work(
        scratch: Path, cli: Callable[..., Run], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "stdin", io.StringIO("time,sensor\n0,0.1\n"))
    monkeypatch.setattr(sys, "stdout", None)  # what Python makes of fd 1 closed (>&-)
    run = _refused(cli, scratch, ["stream", "model.json"], "standard output is closed",
                   "the estimates")
    assert "samples" not in run.err  # refused before the stream started


# --------------------------------------------------------------------------- full disk


class _FullDisk(io.StringIO):
    """A stdout on a disk that fills after `room` characters."""

    def __init__(self, room: int) -> None:
        super().__init__()
        self.room = room

    def write(self, text: str) -> int:
        if self.tell() + len(text) > self.room:
            raise OSError(28, "No space left on device")
        return super().write(text)


@pytest.mark.parametrize("room", [0, 200])  # full at the header; full after a few lines
def test_stream_to_a_full_disk_is_one_error_line(scratch: Path, cli: Callable[..., Run],
                                                 monkeypatch: pytest.MonkeyPatch,
                                                 room: int) -> None:
    out = _FullDisk(room)
    monkeypatch.setattr(sys, "stdout", out)
    _refused(cli, scratch, ["stream", "model.json", "--in", "val.csv"],
             "standard output", "cannot write the estimates", "No space left on device")
    assert 0 < len(out.getvalue().splitlines()) < 10 or room == 0


def test_stream_to_dev_full_is_one_error_line(scratch: Path) -> None:
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "hystkit", "stream", "model.json",
                               "--in", "val.csv"], stdout=full, stderr=subprocess.PIPE,
                              text=True, timeout=300, check=False, cwd=scratch)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and "internal error" not in proc.stderr
    assert proc.stderr.strip().splitlines()[-1] == (
        "hystkit: error: standard output: cannot write the estimates (No space left on "
        "device)")


# --------------------------------------------------------------------------- long names

LONG = "a" * 300


@pytest.mark.parametrize("argv", [
    ["compensate", "model.json", "val.csv", "--out", f"{LONG}.csv"],
    ["compensate", "model.json", "val.csv", "--out", f"{LONG}/x.csv"],
    ["evaluate", "model.json", "val.csv", "--json", f"{LONG}.json"],
    ["fit", "fit.csv", "--model", "mpl", "--out", f"{LONG}.json"],
    ["spectrum", "fit.csv", "--out", LONG],
    ["report", "model.json", "val.csv", "--out", f"{LONG}.html"],
    ["export", "model.json", "--out", LONG],
], ids=["compensate", "under-a-long-folder", "evaluate-json", "fit", "spectrum-folder",
        "report", "export"])
def test_a_300_character_output_name_is_one_error_line(scratch: Path, cli: Callable[..., Run],
                                                       argv: list[str]) -> None:
    _refused(cli, scratch, argv, LONG, "file name too long")


# --------------------------------------------------------------------------- reading options


def test_units_row_on_a_file_without_one_is_refused(scratch: Path,
                                                    cli: Callable[..., Run]) -> None:
    _refused(cli, scratch, ["evaluate", "model.json", "val.csv", "--units-row", "--json",
                            "e.json"], "val.csv", "line 2", "--units-row", "holds numbers",
             "first sample")
    # a real units line is still read (and the samples all kept)
    lines = Path("val.csv").read_text().splitlines(keepends=True)
    Path("units.csv").write_text(lines[0] + "s,mm,\n" + "".join(lines[1:]))
    run = cli("evaluate", "model.json", "units.csv", "--units-row", "--json", "u.json")
    assert run.code == 0, run.err
    assert f"({len(lines) - 1} samples)" in run.out


@pytest.mark.parametrize("data", ["val.csv", "val.parquet"])
def test_mat_var_on_a_file_that_is_not_mat_is_refused(scratch: Path, cli: Callable[..., Run],
                                                      data: str) -> None:
    _refused(cli, scratch, ["evaluate", "model.json", data, "--mat-var", "run1", "--json",
                            "e.json"], data, "--mat-var run1", ".mat")


def test_recording_settings_file_with_a_bom_is_read(scratch: Path,
                                                    cli: Callable[..., Run]) -> None:
    """Its columns are renamed in the file; only the settings (BOM first) map them back."""
    table = pd.read_csv("val.csv").rename(columns={"time": "t", "position": "x",
                                                   "sensor": "r"})
    table.to_csv("own.csv", index=False)
    Path("own.toml").write_bytes(codecs.BOM_UTF8 + b'[columns]\ntime = "t"\nposition = "x"\n'
                                 b'sensor = "r"\n')
    run = cli("evaluate", "model.json", "own.csv", "--json", "e.json")
    assert run.code == 0, run.err
    plain = cli("evaluate", "model.json", "val.csv", "--json", "p.json")
    assert json.loads(Path("e.json").read_text())["r2"] == \
        json.loads(Path("p.json").read_text())["r2"]
    assert plain.code == 0


def test_raw_settings_file_with_a_bom_is_read(tmp_path: Path, cli: Callable[..., Run]) -> None:
    raw = tmp_path / "run.parquet"
    assert cli("simulate-sensor", "--excitation", "sine", "--raw", "--duration", "3",
               "--scope-rate", "2e4", "--out", raw).code == 0
    settings = tmp_path / "run.toml"
    settings.write_bytes(codecs.BOM_UTF8 + settings.read_bytes())
    run = cli("preprocess", raw, "--out", tmp_path / "run.csv")
    assert run.code == 0, run.err
    assert f"with settings from {settings}" in run.out


# --------------------------------------------------------------------------- outputs


def test_report_out_with_another_extension_is_refused(scratch: Path,
                                                      cli: Callable[..., Run]) -> None:
    _refused(cli, scratch, ["report", "model.json", "val.csv", "--out", "r.txt"], "r.txt",
             ".html", "'.txt'")


def test_stream_skips_an_unterminated_last_line(scratch: Path, cli: Callable[..., Run]) -> None:
    """``...,0.00`` may be ``...,0.0031`` cut off mid-write: not compensated, counted."""
    lines = Path("val.csv").read_text().splitlines(keepends=True)[:12]
    Path("cut.csv").write_text("".join(lines) + "0.275,2.2,0.00")
    run = cli("stream", "model.json", "--in", "cut.csv")
    run.clean()
    assert run.code == 0, run.err
    rows = run.out.splitlines()
    assert rows[0] == "time,position_estimate,flags,position_lower,position_upper"  # band
    assert [r.split(",")[0] for r in rows[1:]] == [x.split(",")[0] for x in lines[1:]]
    assert ("hystkit: warning: cut.csv: 1 line(s) unterminated last line (skipped; first at "
            "line 13)") in run.err
    # the same lines, terminated: every one compensated
    Path("whole.csv").write_text("".join(lines) + "0.275,2.2,0.00\n")
    whole = cli("stream", "model.json", "--in", "whole.csv")
    assert whole.out.splitlines()[:-1] == rows and whole.out.splitlines()[-1].startswith(
        "0.275,")
