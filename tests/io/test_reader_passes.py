"""The readers' machinery (issue 10): the .mat child process, the two CSV passes, Parquet types,
and the magnitude limit."""

from __future__ import annotations

import re
from decimal import Decimal
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from scipy.io import savemat

from hystkit.errors import InputError
from hystkit.io import Recording, _csv_reader, _mat_reader, read_recording, write_recording
from hystkit.io._recording import MAX_MAGNITUDE


def _recording(n: int = 50) -> Recording:
    rng = np.random.default_rng(3)
    time = np.arange(n) * 1e-3 + 0.1234567890123
    return Recording(time=time, position=rng.standard_normal(n) * 12.5,
                     sensor=rng.standard_normal(n) * 10.0 ** rng.integers(-12, 3, n))


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return np.array_equal(a.view(np.int64), b.view(np.int64))


# --- .mat in a child process ---------------------------------------------------------------


def _fake_child(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, body: str) -> Path:
    """Replace the child script by `body`; returns a valid .mat file to read."""
    script = tmp_path / "child.py"
    script.write_text(body, encoding="utf-8")
    monkeypatch.setattr(_mat_reader, "_CHILD", script)
    path = tmp_path / "rec.mat"
    savemat(path, {"time": np.arange(3.0), "position": np.ones(3), "sensor": np.ones(3)})
    return path


def _message(path: Path) -> str:
    with pytest.raises(InputError, match=re.escape(f"{path}: cannot read MATLAB file")) as info:
        read_recording(path)
    assert "\n" not in str(info.value)
    return str(info.value)


def test_child_killed_by_a_signal(tmp_path, monkeypatch):
    path = _fake_child(tmp_path, monkeypatch, "import os, signal\nos.kill(os.getpid(), "
                                              "signal.SIGSEGV)\n")
    assert "the reader crashed (signal 11, SIGSEGV); the file is damaged" in _message(path)


def test_child_that_hangs_is_stopped(tmp_path, monkeypatch):
    path = _fake_child(tmp_path, monkeypatch, "import time\ntime.sleep(60)\n")
    monkeypatch.setattr(_mat_reader, "TIMEOUT_BASE_S", 1.0)
    assert "the reader did not finish within 1 s" in _message(path)


def test_child_that_fails_without_a_report(tmp_path, monkeypatch):
    path = _fake_child(tmp_path, monkeypatch, "import sys\nprint('not json')\n"
                                              "sys.exit('boom: broken\\nsecond line')\n")
    assert "the reader failed (exit code 1: second line)" in _message(path)


def test_child_out_of_memory(tmp_path, monkeypatch):
    # The real child with a limit far below what the interpreter needs to load the file.
    # 240 MB of zeros, compressed to a small file: beyond the 200 MB limit whatever the
    # interpreter itself takes (an 8e6-sample file passed or failed with the environment)
    path = tmp_path / "rec.mat"
    savemat(path, {"time": np.arange(3.0), "position": np.ones(3),
                   "sensor": np.zeros(30_000_000)}, do_compression=True)
    monkeypatch.setattr(_mat_reader, "MEMORY_BASE", 200 << 20)
    monkeypatch.setattr(_mat_reader, "MEMORY_FACTOR", 1)
    assert "more memory than the reader may use" in _message(path)


def test_child_passes_back_only_plain_arrays(tmp_path):
    path = tmp_path / "rec.mat"
    savemat(path, {"time": np.arange(4.0), "position": np.arange(4, dtype=np.int16),
                   "sensor": np.ones(4), "notes": {"a": 1}, "other": np.ones(7)})
    contents = _mat_reader.load_mat(path, ["time", "position", "sensor", "notes"], str(path))
    assert set(contents.arrays) == {"time", "position", "sensor"}  # not the struct 'notes'
    assert contents.arrays["position"].dtype == np.int16
    assert contents.variables["other"] == ("float64", (1, 7))
    assert contents.variables["notes"] == ("struct", (1, 1))
    assert contents.fields["notes"] == {"a": ("int64", (1, 1))}


# --- CSV: the fast pass and the text pass agree --------------------------------------------


def test_text_pass_values_are_bit_identical(tmp_path):
    rec = _recording(300)
    path = write_recording(rec, tmp_path / "rec.csv")
    with path.open("a", encoding="utf-8") as file:
        file.write("\n\n")  # trailing blank lines: only the text pass accepts them
    assert _csv_reader._read_numbers(path, True, _csv_reader.Where(str(path))) is None
    back = read_recording(path)
    for name in ("time", "position", "sensor"):
        assert _same_bits(getattr(back, name), getattr(rec, name)), name


@pytest.mark.parametrize("chunk", [1, 2, 3, 7])
def test_text_pass_across_chunks(tmp_path, monkeypatch, chunk):
    monkeypatch.setattr(_csv_reader, "CHUNK_ROWS", chunk)
    rows = [f"{i},{i},{i}" for i in range(10)]
    rows[7] = "7,,7"   # the first bad position cell
    rows[4] = "4,4,x"  # an earlier bad sensor cell: position is reported first (column order)
    path = tmp_path / "rec.csv"
    path.write_text("time,position,sensor\n" + "\n".join(rows) + "\n\n\n", encoding="utf-8")
    with pytest.raises(InputError, match=re.escape("column 'position', row 8 (line 9): empty")):
        read_recording(path)
    rows[7], rows[4] = "7,7,7", "4,4,4"
    path.write_text("time,position,sensor,note\n" + "\n".join(rows) + "\n,,,\n\n",
                    encoding="utf-8")
    np.testing.assert_array_equal(read_recording(path).time, np.arange(10.0))


def test_text_pass_long_row_in_a_later_chunk(tmp_path, monkeypatch):
    monkeypatch.setattr(_csv_reader, "CHUNK_ROWS", 3)
    rows = [f"{i},{i},{i}" for i in range(10)]
    rows[8] = "8,8,8,8"
    path = tmp_path / "rec.csv"
    path.write_text("time,position,sensor\n" + "\n".join(rows) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match=re.escape("row 9 (line 10): 4 fields but the header")):
        read_recording(path)


def test_not_utf8_position_in_a_later_block(tmp_path):
    path = tmp_path / "rec.csv"
    body = "".join(f"{i},{i},{i}\n" for i in range(200_000))  # about 2 MB: several blocks
    data = ("time,position,sensor\n" + body).encode() + b"1,2,\xff\n"
    path.write_bytes(data)
    with pytest.raises(InputError, match=re.escape(
            f"not a UTF-8 text file (line 200002, byte offset {len(data) - 2}: invalid start")):
        read_recording(path)


def test_header_too_wide(tmp_path):
    path = tmp_path / "rec.csv"
    path.write_text("time,position,sensor" + ",x" * 2000 + "\n1,2,3\n", encoding="utf-8")
    with pytest.raises(InputError, match="the header line has 2003 fields; a recording has at "
                                         "most 1000 columns"):
        read_recording(path)


# --- Parquet -------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", [pa.int8(), pa.uint32(), pa.float16(), pa.float32(),
                                  pa.decimal128(10, 3)])
def test_parquet_numeric_types_are_read(tmp_path, kind):
    values = [0.0, 0.5, 1.0, 1.5] if pa.types.is_floating(kind) else [0, 1, 2, 3]
    column = pa.array([Decimal(v) for v in values] if pa.types.is_decimal(kind) else values,
                      kind)
    path = tmp_path / "rec.parquet"
    pq.write_table(pa.table({"time": [0.0, 1.0, 2.0, 3.0], "position": column,
                             "sensor": [1.0, 2.0, 3.0, 4.0]}), path)
    np.testing.assert_array_equal(read_recording(path).position, np.asarray(values, float))


def test_parquet_with_corrupt_pandas_metadata_is_read(tmp_path):
    # pandas' JSON metadata is not consulted: damage there does not matter.
    table = pa.Table.from_pandas(pd.DataFrame({"time": [0.0, 1.0], "position": [1.0, 2.0],
                                               "sensor": [3.0, 4.0]}))
    table = table.replace_schema_metadata({b"pandas": b"{not json"})
    path = tmp_path / "rec.parquet"
    pq.write_table(table, path)
    assert read_recording(path).n_samples == 2


# --- magnitudes ----------------------------------------------------------------------------


@pytest.mark.parametrize("value", [1.7e308, -1e101, 2 * MAX_MAGNITUDE])
def test_recording_refuses_huge_values(value):
    with pytest.raises(InputError, match=re.escape(
            f"<memory>: column 'sensor', sample 2: value {value:.6g} is too large; hystkit "
            f"accepts magnitudes up to 1e+100")):
        Recording(time=[0.0, 1.0, 2.0], sensor=[1.0, value, 2.0])


def test_recording_accepts_the_limit():
    rec = Recording(time=[0.0, 1.0, 2.0], sensor=[MAX_MAGNITUDE, -MAX_MAGNITUDE, 0.0])
    assert rec.sensor[0] == MAX_MAGNITUDE


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mat"])
def test_read_recordings_are_read_only(tmp_path, suffix):
    rec = _recording()
    path = tmp_path / f"rec{suffix}"
    if suffix == ".mat":
        savemat(path, {"time": rec.time, "position": rec.position, "sensor": rec.sensor})
    else:
        write_recording(rec, path)
    back = read_recording(path)
    for name in ("time", "position", "sensor"):
        values = getattr(back, name)
        assert values.dtype == np.float64 and values.ndim == 1
        with pytest.raises(ValueError, match="read-only"):
            values[0] = 1.0
    assert back.source == str(path) and back.n_samples == rec.n_samples
