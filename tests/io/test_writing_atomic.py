"""Atomic outputs (issue 10): complete or absent, exclusive without force, no temporaries left."""

from __future__ import annotations

import errno
import os
import re
import stat
from pathlib import Path

import numpy as np
import pytest

from hystkit.errors import NonFiniteError, OutputError, OutputExistsError
from hystkit.io import (
    Recording,
    atomic_folder,
    atomic_output,
    atomic_outputs,
    check_output_path,
    write_json,
    write_recording,
)
from hystkit.io._output_checks import TEMP_MARK


def _names(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def _recording(n: int = 5) -> Recording:
    t = np.arange(n) * 0.01
    return Recording(time=t, sensor=np.sin(t), position=np.cos(t), source="test")


def test_output_appears_with_usual_permissions_and_no_temporary(tmp_path: Path) -> None:
    path = write_json({"a": 1}, tmp_path / "x.json")
    assert path.read_text() == '{\n  "a": 1\n}\n'
    assert _names(tmp_path) == ["x.json"]
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask


def test_existing_output_is_refused_without_force_and_replaced_with(tmp_path: Path) -> None:
    path = tmp_path / "x.json"
    path.write_text("old")
    with pytest.raises(OutputExistsError, match="pass --force"):
        write_json({"a": 1}, path)
    assert path.read_text() == "old"
    write_json({"a": 2}, path, force=True)
    assert '"a": 2' in path.read_text()
    assert _names(tmp_path) == ["x.json"]


@pytest.mark.parametrize("exc", [RuntimeError, KeyboardInterrupt, SystemExit])
def test_failure_inside_the_block_leaves_target_and_folder_as_they_were(
        tmp_path: Path, exc: type[BaseException]) -> None:
    (tmp_path / "keep.csv").write_text("old")
    for target in (tmp_path / "keep.csv", tmp_path / "new" / "deeper" / "x.csv"):
        with pytest.raises(exc), atomic_output(target, force=True) as tmp:
            assert TEMP_MARK in tmp.name and tmp.suffix == ".csv" and tmp.parent == target.parent
            tmp.write_text("half")
            raise exc()
    assert _names(tmp_path) == ["keep.csv"]  # the created parent folders went too
    assert (tmp_path / "keep.csv").read_text() == "old"


def test_target_created_meanwhile_wins_over_an_exclusive_writer(tmp_path: Path) -> None:
    path = tmp_path / "x.csv"
    with pytest.raises(OutputExistsError, match="already exists"), atomic_output(path) as tmp:
        tmp.write_text("mine")
        path.write_text("theirs")  # a concurrent writer published first
    assert path.read_text() == "theirs"
    assert _names(tmp_path) == ["x.csv"]


def test_without_hard_links_creation_stays_exclusive(tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    def no_link(*_: object) -> None:
        raise OSError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_link)
    path = tmp_path / "x.csv"
    with atomic_output(path) as tmp:
        tmp.write_text("mine")
    assert path.read_text() == "mine"
    with pytest.raises(OutputExistsError), atomic_output(tmp_path / "y.csv") as tmp:
        tmp.write_text("mine")
        (tmp_path / "y.csv").write_text("theirs")
    assert (tmp_path / "y.csv").read_text() == "theirs"
    assert _names(tmp_path) == ["x.csv", "y.csv"]


def test_folder_appears_complete_or_not_at_all(tmp_path: Path) -> None:
    out = tmp_path / "report"
    with pytest.raises(KeyboardInterrupt), atomic_folder(out, names=["a.json"]) as tmp:
        write_json({"a": 1}, tmp / "a.json")
        raise KeyboardInterrupt
    assert _names(tmp_path) == []
    with atomic_folder(out, names=["a.json", "b.json"]) as tmp:
        write_json({"a": 1}, tmp / "a.json")
        assert not out.exists()
        write_json({"b": 1}, tmp / "b.json")
    assert _names(tmp_path) == ["report", "report/a.json", "report/b.json"]


def test_existing_folder_changes_only_when_every_file_can_go_in(tmp_path: Path) -> None:
    out = tmp_path / "report"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    with atomic_folder(out, names=["a.json"]) as tmp:  # new names: merged without --force
        write_json({"a": 1}, tmp / "a.json")
    # c appears meanwhile: b must not stay behind
    with pytest.raises(OutputExistsError), atomic_folder(out, names=["b.json", "c.json"]) as tmp:
        write_json({"b": 1}, tmp / "b.json")
        write_json({"c": 1}, tmp / "c.json")
        (out / "c.json").write_text("theirs")
    assert _names(tmp_path) == ["report", "report/a.json", "report/c.json", "report/mine.txt"]
    with atomic_folder(out, force=True, names=["a.json"]) as tmp:
        write_json({"a": 2}, tmp / "a.json")
    assert '"a": 2' in (out / "a.json").read_text()
    assert (out / "mine.txt").read_text() == "keep"


def test_non_finite_columns_are_refused_by_name_and_row(tmp_path: Path) -> None:
    rec = _recording()
    estimate = np.array([0.0, 1.0, np.inf, np.nan, 2.0])
    with pytest.raises(NonFiniteError, match=r"'position_estimate' row 3 is inf \(2 non-finite"):
        write_recording(rec, tmp_path / "x.csv", extra={"position_estimate": estimate})
    assert _names(tmp_path) == []
    write_recording(rec, tmp_path / "x.parquet", extra={"flag": np.zeros(5, int)})
    assert _names(tmp_path) == ["x.parquet"]


@pytest.mark.parametrize(("obj", "where"), [
    ({"sine": {"r2": float("nan")}}, "sine.r2 is nan"),
    ({"params": {"a": np.array([1.0, -np.inf])}}, "params.a[1] is -inf"),
    ([1.0, np.float64("inf")], "[1] is inf"),
])
def test_non_finite_json_is_refused_with_its_key(tmp_path: Path, obj: object,
                                                  where: str) -> None:
    with pytest.raises(NonFiniteError, match=rf"x\.json: value {re.escape(where)}"):
        write_json(obj, tmp_path / "x.json")
    assert _names(tmp_path) == []


def test_unwritable_places_are_refused_before_any_work(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("")
    with pytest.raises(OutputError, match="is a file, not a folder"):
        check_output_path(tmp_path / "file" / "x.csv")
    with pytest.raises(OutputError, match="cannot write into /proc"):
        check_output_path("/proc/x.csv")
    with pytest.raises(OutputError, match="is a folder"):
        check_output_path(tmp_path, force=True)
    with pytest.raises(OutputError, match="also an input"):
        check_output_path(tmp_path / "file", force=True, inputs=[tmp_path / "file"])
    assert _names(tmp_path) == ["file"]





def test_files_that_belong_together_appear_together_or_not_at_all(tmp_path: Path) -> None:
    data, report = tmp_path / "out.csv", tmp_path / "sub" / "out.json"
    with pytest.raises(KeyboardInterrupt), atomic_outputs([data, report]) as (t1, t2):
        t1.write_text("data")
        raise KeyboardInterrupt
    assert _names(tmp_path) == []
    data.write_text("old data")
    # with force, the report's clash undoes the data file's replacement
    with pytest.raises(OutputError, match="out.json"):  # noqa: SIM117  (it fails at publication)
        with atomic_outputs([data, report], force=True) as (t1, t2):
            t1.write_text("new data")
            t2.write_text("new report")
            report.mkdir()  # a folder where the report should go cannot be replaced
    assert data.read_text() == "old data"
    report.rmdir()
    with atomic_outputs([data, report], force=True) as (t1, t2):
        t1.write_text("new data")
        t2.write_text("new report")
    assert (data.read_text(), report.read_text()) == ("new data", "new report")
    assert _names(tmp_path) == ["out.csv", "sub", "sub/out.json"]


@pytest.mark.parametrize("name", [".", ".."])
def test_folder_output_may_be_the_current_folder_or_its_parent(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str) -> None:
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    with atomic_folder(name, names=["a.json"]) as tmp:
        write_json({"a": 1}, tmp / "a.json")
    where = work if name == "." else tmp_path
    assert (where / "a.json").is_file()
    assert _names(tmp_path) == sorted(["work", "work/a.json" if name == "." else "a.json"])
