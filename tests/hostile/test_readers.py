"""Hostile recordings through the CLI: every broken file gives exit 2 and one line (issue 10).

Each case copies a valid input (the session's ``good`` files) into ``tmp_path``, breaks the
copy, runs ``evaluate``, ``compensate`` or ``fit`` on it with outputs aimed into ``tmp_path``,
and checks: exit code 2, exactly one ``hystkit: error:`` line naming the file (and the
column/variable and row/sample where there is one), no traceback, and ``tmp_path`` holding
exactly what it held before (nothing written, no temporary left behind).

The damaged ``.mat`` files change one byte that made scipy 1.17's ``loadmat`` crash in a
fuzzing run (offset 145: the array-flags byte; 176/177: the data-type field of the first
variable's real part). With the session's ``val.mat`` the first, second and fourth case are
a SIGSEGV every time, the third a SIGSEGV, SIGBUS or an exception depending on the memory
layout; so the cases ask only for "cannot read MATLAB file" (the crash path itself is tested
deterministically in ``tests/io/test_reader_passes.py``). They run in-process on purpose: the
reader parses ``.mat`` in a child process, so pytest itself surviving them is part of the
check.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from scipy import sparse
from scipy.io import savemat

from hystkit.io import read_recording

from .conftest import Run, entries, snapshot

COMMANDS = ("evaluate", "compensate", "fit")


def _run(cli: Callable[..., Run], good: dict[str, Path], command: str, data: Path) -> Run:
    out = data.parent / "out"
    if command == "evaluate":
        return cli("evaluate", good["model"], data, "--json", out / "scores.json")
    if command == "compensate":
        return cli("compensate", good["model"], data, "--out", out / "compensated.csv")
    return cli("fit", data, "--cells", "1", "--out", out / "model.json")


def _refused(cli: Callable[..., Run], good: dict[str, Path], command: str, data: Path,
             *fragments: object) -> str:
    """Run `command` on `data`; exit 2, one error line naming `data` and `fragments`, no output."""
    folder = data.parent
    before, listed = snapshot(folder), entries(folder)
    run = _run(cli, good, command, data)
    assert run.code == 2, (run.code, run.out, run.err)
    line = run.error_line(data, *fragments)
    assert snapshot(folder) == before
    assert entries(folder) == listed
    return line


def _copy(good: dict[str, Path], key: str, tmp_path: Path, name: str | None = None) -> Path:
    target = tmp_path / (name or good[key].name)
    shutil.copyfile(good[key], target)
    target.chmod(0o644)
    return target


def _table(good: dict[str, Path]) -> pd.DataFrame:
    return pd.read_csv(good["val"])


def _mat(tmp_path: Path, good: dict[str, Path], **replace: object) -> Path:
    columns = {name: np.asarray(values) for name, values in _table(good).items()}
    columns.update(replace)
    path = tmp_path / "rec.mat"
    savemat(path, columns)
    return path


def _parquet(tmp_path: Path, good: dict[str, Path], **replace: pa.Array) -> Path:
    table = pa.Table.from_pandas(_table(good), preserve_index=False)
    for name, column in replace.items():
        table = table.set_column(table.schema.get_field_index(name), name, column)
    path = tmp_path / "rec.parquet"
    pq.write_table(table, path)
    return path


def _csv_with(tmp_path: Path, good: dict[str, Path], row: int, column: str, cell: str) -> Path:
    """val.csv with the cell at 0-based data `row` of `column` replaced by the text `cell`."""
    lines = good["val"].read_text(encoding="utf-8").splitlines()
    index = lines[0].split(",").index(column)
    fields = lines[row + 1].split(",")
    fields[index] = cell
    lines[row + 1] = ",".join(fields)
    path = tmp_path / "rec.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


# --- MATLAB --------------------------------------------------------------------------------


@pytest.mark.parametrize(("offset", "value", "command"),
                         [(145, 0xFF, "evaluate"), (176, 0x00, "compensate"),
                          (177, 0xFF, "fit"), (145, 0x0B, "compensate")])
def test_mat_with_a_byte_that_crashed_scipy(cli, good, tmp_path, offset, value, command):
    path = _copy(good, "val_mat", tmp_path)
    data = bytearray(path.read_bytes())
    data[offset] = value
    path.write_bytes(bytes(data))
    _refused(cli, good, command, path, "cannot read MATLAB file")


def test_mat_truncated(cli, good, tmp_path):
    path = _copy(good, "val_mat", tmp_path)
    path.write_bytes(good["val_mat"].read_bytes()[:1000])
    _refused(cli, good, "evaluate", path, "cannot read MATLAB file")


def test_mat_header_only(cli, good, tmp_path):
    path = _copy(good, "val_mat", tmp_path)
    path.write_bytes(good["val_mat"].read_bytes()[:128])
    _refused(cli, good, "compensate", path, "missing required variable 'time'",
             "variables found: none")


@pytest.mark.parametrize(("value", "fragment"), [
    ({"a": 1.0, "b": 2.0}, "not real numbers (dtype [("),  # a MATLAB struct
    (np.array([1.0, "x"], dtype=object), "not real numbers (dtype object)"),  # a cell array
    ("position as text", "not real numbers (dtype <U"),
    (np.ones(3) + 1j, "not real numbers (dtype complex128)"),
])
def test_mat_variable_that_is_not_real_numbers(cli, good, tmp_path, value, fragment):
    path = _mat(tmp_path, good, position=value)
    _refused(cli, good, "evaluate", path, "variable 'position'", fragment)


def test_mat_variables_of_different_lengths(cli, good, tmp_path):
    path = _mat(tmp_path, good, position=np.array([True, False, True]))  # logical -> uint8
    _refused(cli, good, "fit", path, "variables have different lengths", "position 3")


def test_mat_sparse_variable(cli, good, tmp_path):
    n = len(_table(good))
    path = _mat(tmp_path, good, sensor=sparse.csc_matrix(np.ones((n, 1))))
    _refused(cli, good, "compensate", path, "variable 'sensor'", "sparse matrix")


def test_mat_v73_hdf5(cli, good, tmp_path):
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "rec.mat"
    with h5py.File(path, "w", userblock_size=512) as file:
        for name, values in _table(good).items():
            file[name] = np.asarray(values)
    with path.open("r+b") as raw:  # MATLAB writes a v5-style text header into the user block
        raw.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan 1 00:00:00 2024 "
                  b"HDF5 schema 1.00 .".ljust(116) + b"\0" * 8 + b"\x00\x02IM")
    _refused(cli, good, "fit", path, "v7.3 (HDF5) files are not supported")


def test_mat_huge_value(cli, good, tmp_path):
    position = np.asarray(_table(good)["position"]).copy()
    position[7] = 1.7e308
    path = _mat(tmp_path, good, position=position)
    _refused(cli, good, "evaluate", path, "variable 'position', sample 8", "too large")


# --- Parquet -------------------------------------------------------------------------------


def test_parquet_truncated(cli, good, tmp_path):
    path = _copy(good, "val_parquet", tmp_path)
    path.write_bytes(good["val_parquet"].read_bytes()[:-100])
    _refused(cli, good, "evaluate", path, "cannot read Parquet file")


def test_parquet_dictionary_with_nulls(cli, good, tmp_path):
    frame = _table(good)
    values = frame["position"].tolist()
    values[4] = None
    frame["position"] = pd.Categorical(values)  # stored dictionary-encoded, with a null
    path = tmp_path / "rec.parquet"
    frame.to_parquet(path, index=False)
    _refused(cli, good, "evaluate", path, "column 'position', row 5", "missing or NaN value")


def test_parquet_dictionary_without_nulls_is_read(tmp_path, good):
    frame = _table(good)
    expected = frame["position"].to_numpy()
    frame["position"] = pd.Categorical(expected)
    path = tmp_path / "rec.parquet"
    frame.to_parquet(path, index=False)
    np.testing.assert_array_equal(read_recording(path).position, expected)


def test_parquet_nullable_int_with_null(cli, good, tmp_path):
    n = len(_table(good))
    column = pa.array([*range(10), None, *range(11, n)], pa.int64())
    path = _parquet(tmp_path, good, sensor=column)
    _refused(cli, good, "compensate", path, "column 'sensor', row 11", "missing or NaN value")


@pytest.mark.parametrize(("make", "fragment"), [
    (lambda n: pa.array([True] * n), "not numeric (dtype bool)"),
    (lambda n: pa.array(np.arange(n).astype("datetime64[ms]")), "not numeric (dtype timestamp"),
    (lambda n: pa.array([[1.0, 2.0]] * n), "not numeric (dtype list"),
    (lambda n: pa.array([{"x": 1.0}] * n), "not numeric (dtype struct"),
    (lambda n: pa.array(["a"] * n).dictionary_encode(), "row 1: non-numeric value 'a'"),
    (lambda n: pa.array(["1.5", None] + ["2"] * (n - 2)).dictionary_encode(), "row 2: empty cell"),
])
def test_parquet_column_of_another_type(cli, good, tmp_path, make, fragment):
    path = _parquet(tmp_path, good, position=make(len(_table(good))))
    _refused(cli, good, "evaluate", path, "column 'position'", fragment)


def test_parquet_huge_value(cli, good, tmp_path):
    values = _table(good)["sensor"].to_numpy().copy()
    values[2] = -1.7e308
    path = _parquet(tmp_path, good, sensor=pa.array(values))
    _refused(cli, good, "compensate", path, "column 'sensor', row 3", "too large")


# --- CSV -----------------------------------------------------------------------------------


def test_csv_truncated_after_a_comma(cli, good, tmp_path):
    text = good["val"].read_bytes()
    cut = text.rindex(b",", 0, len(text) // 2) + 1
    path = tmp_path / "rec.csv"
    path.write_bytes(text[:cut])
    rows = text[:cut].count(b"\n")  # the cut row is data row `rows`, on line rows + 1
    _refused(cli, good, "evaluate", path, f"row {rows} (line {rows + 1}): empty cell")


@pytest.mark.parametrize("command", COMMANDS)
def test_csv_huge_finite_value(cli, good, tmp_path, command):
    path = _csv_with(tmp_path, good, 9, "position", "1.7e308")
    _refused(cli, good, command, path, "column 'position', row 10 (line 11)",
             "value 1.7e+308 is too large")


@pytest.mark.parametrize(("cell", "fragment"), [("nan", "missing or NaN value"),
                                                ("inf", "infinite value inf"),
                                                ("-Infinity", "infinite value -inf"),
                                                ("", "empty cell"),
                                                ("1.5\x00", "non-numeric value '1.5\\x00'")])
def test_csv_bad_cell(cli, good, tmp_path, cell, fragment):
    path = _csv_with(tmp_path, good, 3, "sensor", cell)
    _refused(cli, good, "compensate", path, "column 'sensor', row 4 (line 5)", fragment)


def test_csv_huge_field(cli, good, tmp_path):
    path = _csv_with(tmp_path, good, 0, "time", "9" * 1_000_000 + "x")
    line = _refused(cli, good, "evaluate", path, "column 'time', row 1 (line 2)",
                    "(1000001 characters)")
    assert len(line) < 500


def test_csv_not_utf8(cli, good, tmp_path):
    path = _csv_with(tmp_path, good, 5, "position", "1.5")
    path.write_bytes(path.read_bytes().replace(b"1.5", b"1.5\xb5", 1))
    _refused(cli, good, "fit", path, "not a UTF-8 text file (line 7, byte offset")


def test_csv_utf16(cli, good, tmp_path):
    path = tmp_path / "rec.csv"
    path.write_bytes(good["val"].read_text(encoding="utf-8").encode("utf-16"))
    _refused(cli, good, "evaluate", path, "not a UTF-8 text file (line 1, byte offset 0")


def test_csv_unbalanced_quote(cli, good, tmp_path):
    path = _csv_with(tmp_path, good, 2, "sensor", '"0.5')
    _refused(cli, good, "compensate", path, "row 3 (line 4): a quote opened here is never closed")


def test_csv_long_row(cli, good, tmp_path):
    path = _csv_with(tmp_path, good, 6, "sensor", "0.5,7")
    _refused(cli, good, "fit", path, "row 7 (line 8): 4 fields but the header names 3 columns")


def test_csv_separator_that_cannot_be_told(cli, good, tmp_path):
    # a ';'-separated file is read since issue 27.1; one that ';' and ',' split alike is not
    path = tmp_path / "rec.csv"
    lines = good["val"].read_text(encoding="utf-8").splitlines()
    path.write_text("\n".join(line.replace(",", ";", 1) for line in lines) + "\n",
                    encoding="utf-8")
    _refused(cli, good, "evaluate", path, "line 1: cannot tell the field separator: comma and "
             "semicolon each split", "pass --sep ',' or --sep ';'")


def test_csv_one_row(cli, good, tmp_path):
    path = tmp_path / "rec.csv"
    path.write_text("\n".join(good["val"].read_text(encoding="utf-8").splitlines()[:2]) + "\n",
                    encoding="utf-8")
    _refused(cli, good, "compensate", path, "only 1 sample(s)")


def test_csv_two_rows_cannot_be_fitted(cli, good, tmp_path):
    path = tmp_path / "rec.csv"
    path.write_text("\n".join(good["val"].read_text(encoding="utf-8").splitlines()[:3]) + "\n",
                    encoding="utf-8")
    _refused(cli, good, "fit", path, "2 samples")


def test_directory_named_like_a_recording(cli, good, tmp_path):
    path = tmp_path / "x.csv"
    path.mkdir()
    _refused(cli, good, "evaluate", path, "not a regular file")


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0,
                    reason="root reads files regardless of their permissions")
def test_unreadable_file(cli, good, tmp_path):
    path = _copy(good, "val", tmp_path)
    path.chmod(0)
    _refused(cli, good, "compensate", path, "cannot read the file (Permission denied)")


# --- odd but valid CSV ---------------------------------------------------------------------


@pytest.mark.parametrize(("bom", "newline"), [(True, "\n"), (False, "\r\n"), (True, "\r\n")])
def test_csv_bom_and_crlf_read_the_same_values(cli, good, tmp_path, bom, newline):
    text = good["val"].read_text(encoding="utf-8").splitlines()
    path = tmp_path / "rec.csv"
    path.write_bytes(("\ufeff" if bom else "").encode() + newline.join(text).encode() + b"\n")
    run = cli("compensate", good["model"], path, "--out", tmp_path / "a.csv")
    assert run.code == 0, run.err
    run = cli("compensate", good["model"], good["val"], "--out", tmp_path / "b.csv")
    assert run.code == 0, run.err
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
