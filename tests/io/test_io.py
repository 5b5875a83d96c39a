"""Tests for hystkit.io: round trips, one test per input error, overwrite rules."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.io import savemat

from hystkit.errors import InputError, OutputError, OutputExistsError
from hystkit.io import Recording, read_recording, write_json, write_recording


def _recording(n: int = 200, seed: int = 0) -> Recording:
    # Irrational-looking values with full 53-bit mantissas catch any precision loss.
    rng = np.random.default_rng(seed)
    time = np.arange(n) * 1e-3 + 0.1234567890123
    position = np.sin(2 * np.pi * 3.7 * time) * 12.5 + rng.standard_normal(n) * 1e-3
    sensor = rng.standard_normal(n) * 10.0 ** rng.integers(-12, 3, n)
    return Recording(time=time, sensor=sensor, position=position)


def _bits_equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and np.array_equal(a.view(np.int64), b.view(np.int64))


def _csv(tmp_path: Path, text: str, name: str = "rec.csv") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _raises(path: Path, *fragments: str, need_position: bool = True) -> str:
    """Read `path`, expect one InputError containing the file name and every fragment."""
    with pytest.raises(InputError, match=re.escape(str(path))) as info:
        read_recording(path, need_position=need_position)
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, message
    assert "\n" not in message
    return message


GOOD = "time,position,sensor\n0.0,1.0,0.1\n0.1,1.5,0.2\n0.2,2.0,0.3\n0.3,2.5,0.4\n"


# --- round trips -------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_write_read_round_trip_is_bit_exact(tmp_path: Path, suffix: str) -> None:
    rec = _recording()
    path = write_recording(rec, tmp_path / f"out{suffix}")
    back = read_recording(path)
    for name in ("time", "position", "sensor"):
        assert _bits_equal(getattr(back, name), getattr(rec, name)), name
    assert back.source == str(path)


def test_mat_round_trip(tmp_path: Path) -> None:
    rec = _recording()
    path = tmp_path / "rec.mat"
    # Row and column vectors are both accepted.
    savemat(path, {"time": rec.time, "position": rec.position[:, None], "sensor": rec.sensor,
                   "comment": "extra variables are ignored"})
    back = read_recording(path)
    for name in ("time", "position", "sensor"):
        assert _bits_equal(getattr(back, name), getattr(rec, name)), name


def test_csv_extra_columns_whitespace_bom_and_trailing_blank_lines(tmp_path: Path) -> None:
    text = "\ufeff note , time,sensor ,position\nA, 0, 1e-3,5\nB,0.5,-2,6\nC,1,3,7\n\n\n"
    rec = read_recording(_csv(tmp_path, text))
    np.testing.assert_array_equal(rec.time, [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(rec.sensor, [1e-3, -2.0, 3.0])
    np.testing.assert_array_equal(rec.position, [5.0, 6.0, 7.0])


def test_need_position_false(tmp_path: Path) -> None:
    path = _csv(tmp_path, "time,sensor\n0,1\n1,2\n2,3\n")
    rec = read_recording(path, need_position=False)
    assert rec.position is None and not rec.has_position()
    _raises(path, "missing required column 'position'", "columns found: 'time', 'sensor'")
    # A position column that is present is still read.
    assert read_recording(_csv(tmp_path, GOOD, "p.csv"), need_position=False).has_position()


def test_need_position_false_round_trip_without_position(tmp_path: Path) -> None:
    rec = Recording(time=[0.0, 0.5, 1.0], sensor=[3, 2, 1])
    path = write_recording(rec, tmp_path / "nopos.parquet")
    assert list(pd.read_parquet(path).columns) == ["time", "sensor"]
    assert not read_recording(path, need_position=False).has_position()


# --- Recording ---------------------------------------------------------------------------


def test_recording_properties_and_read_only_copies() -> None:
    time = np.linspace(0.0, 1.0, 11)
    sensor = np.arange(11)  # integers are converted
    rec = Recording(time=time, sensor=sensor)
    assert rec.n_samples == 11
    assert rec.dt == pytest.approx(0.1)
    assert rec.fs == pytest.approx(10.0)
    assert rec.sensor.dtype == np.float64
    time[0] = -5.0  # the recording holds a copy
    assert rec.time[0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        rec.time[0] = 1.0
    with pytest.raises(AttributeError):
        rec.time = time  # type: ignore[misc]


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"time": [0, 1, 2], "sensor": [1, 2]}, "columns have different lengths: time 3, sensor 2"),
        ({"time": [0, 1, 2], "sensor": [1, np.nan, 2]}, "column 'sensor', sample 2: missing or NaN"),
        ({"time": [0, 1, 1], "sensor": [1, 2, 3]}, "column 'time', sample 3: time is not strictly"),
        ({"time": [0.0], "sensor": [1.0]}, "only 1 sample(s); a recording needs at least 2"),
        ({"time": [0, 1, 2], "sensor": ["a", "b", "c"]}, "column 'sensor': not real numbers"),
        ({"time": np.zeros((2, 2)), "sensor": [1, 2]}, "must be a row or column vector"),
    ],
)
def test_recording_validates(kwargs: dict, fragment: str) -> None:
    with pytest.raises(InputError, match=re.escape("<memory>: ")) as info:
        Recording(**kwargs)
    assert fragment in str(info.value)


# --- input errors ------------------------------------------------------------------------


def test_unsupported_suffix(tmp_path: Path) -> None:
    _raises(_csv(tmp_path, GOOD, "rec.txt"), "unsupported file type '.txt'",
            "accepted: .csv, .parquet, .mat")


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mat"])
def test_missing_file(tmp_path: Path, suffix: str) -> None:
    _raises(tmp_path / f"absent{suffix}", "file not found")


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mat"])
def test_zero_byte_file(tmp_path: Path, suffix: str) -> None:
    _raises(_csv(tmp_path, "", f"empty{suffix}"), "file is empty (0 bytes)")


def test_header_only(tmp_path: Path) -> None:
    _raises(_csv(tmp_path, "time,position,sensor\n"), "no data rows below the header")


def test_blank_lines_only(tmp_path: Path) -> None:
    _raises(_csv(tmp_path, "\n\n"), "file is empty (no header row)")


def test_missing_column_lists_found_columns(tmp_path: Path) -> None:
    _raises(_csv(tmp_path, "time,pos,sensor,temp\n0,1,2,3\n"),
            "missing required column 'position'; columns found: 'time', 'pos', 'sensor', 'temp'")


def test_missing_header_hint(tmp_path: Path) -> None:
    _raises(_csv(tmp_path, "0,1,2\n1,2,3\n"), "columns found: '0', '1', '2'",
            "the first line must be a comma-separated header")


def test_duplicate_column(tmp_path: Path) -> None:
    _raises(_csv(tmp_path, "time,position,sensor,time\n0,1,2,3\n"),
            "column 'time': appears 2 times in the header")


def test_non_numeric_cell(tmp_path: Path) -> None:
    text = GOOD + "0.4,3.0,abc\n0.5,3.5,def\n"
    _raises(_csv(tmp_path, text), "column 'sensor', row 5 (line 6): non-numeric value 'abc'")


def test_empty_cell(tmp_path: Path) -> None:
    text = "time,position,sensor\n0,1,2\n1,,3\n2,x,4\n"
    _raises(_csv(tmp_path, text), "column 'position', row 2 (line 3): empty cell")


def test_short_row_is_an_empty_cell(tmp_path: Path) -> None:
    text = "time,position,sensor\n0,1,2\n1,2,3\n2,3\n3,4,5\n"
    _raises(_csv(tmp_path, text), "column 'sensor', row 3 (line 4): empty cell")


def test_blank_line_inside_data_keeps_line_numbers(tmp_path: Path) -> None:
    text = "time,position,sensor\n0,1,2\n\n2,3,4\n"
    _raises(_csv(tmp_path, text), "column 'time', row 2 (line 3): empty cell")


def test_long_row(tmp_path: Path) -> None:
    text = "time,position,sensor\n0,1,2\n1,2,3,4\n"
    _raises(_csv(tmp_path, text), "row 2 (line 3): 4 fields but the header names 3 columns")


@pytest.mark.parametrize(("cell", "fragment"),
                         [("nan", "missing or NaN value"), ("-inf", "infinite value -inf")])
def test_non_finite_cell(tmp_path: Path, cell: str, fragment: str) -> None:
    text = f"time,position,sensor\n0,1,2\n1,{cell},3\n2,3,4\n"
    _raises(_csv(tmp_path, text), f"column 'position', row 2 (line 3): {fragment}")


def test_not_utf8(tmp_path: Path) -> None:
    path = tmp_path / "latin1.csv"
    path.write_bytes("time,position,sensor\n0,1,2\n1,2,3 µ\n".encode("latin-1"))
    _raises(path, "not a UTF-8 text file")


def test_time_not_increasing(tmp_path: Path) -> None:
    text = "time,position,sensor\n0,1,2\n0.1,1,2\n0.2,1,2\n0.2,1,2\n0.3,1,2\n"
    _raises(_csv(tmp_path, text),
            "column 'time', row 4 (line 5): time is not strictly increasing: 0.2 s follows 0.2 s")


def test_non_uniform_sampling(tmp_path: Path) -> None:
    times = [0.0, 0.01, 0.02, 0.03, 0.0405, 0.05, 0.06]
    text = "time,position,sensor\n" + "".join(f"{t},1,2\n" for t in times)
    _raises(_csv(tmp_path, text), "column 'time', row 5 (line 6): non-uniform sampling: step 0.0105 s",
            "median step 0.01 s", "resample")


def test_jitter_within_one_percent_is_accepted(tmp_path: Path) -> None:
    times = [0.0, 0.01, 0.02, 0.03, 0.04009, 0.05, 0.06]
    text = "time,position,sensor\n" + "".join(f"{t},1,2\n" for t in times)
    assert read_recording(_csv(tmp_path, text)).n_samples == 7


def test_single_sample(tmp_path: Path) -> None:
    _raises(_csv(tmp_path, "time,position,sensor\n0,1,2\n"),
            "only 1 sample(s); a recording needs at least 2")


def test_parquet_errors(tmp_path: Path) -> None:
    frame = pd.DataFrame({"time": [0.0, 1.0, 2.0], "position": [1.0, None, 3.0],
                          "sensor": ["1", "2", "x"]})
    path = tmp_path / "rec.parquet"
    frame.to_parquet(path)
    _raises(path, "column 'sensor', row 3: non-numeric value 'x'")
    frame["sensor"] = [1.0, 2.0, 3.0]
    frame.to_parquet(path)
    message = _raises(path, "column 'position', row 2: missing or NaN value")
    assert "line" not in message
    frame.drop(columns="sensor").to_parquet(path)
    _raises(path, "missing required column 'sensor'; columns found: 'time', 'position'")
    path.write_bytes(b"not parquet at all")
    _raises(path, "cannot read Parquet file")


def test_mat_errors(tmp_path: Path) -> None:
    path = tmp_path / "rec.mat"
    savemat(path, {"time": np.arange(4.0), "position": np.ones(4), "sensor": np.ones(3)})
    _raises(path, "variables have different lengths: time 4, position 4, sensor 3")
    savemat(path, {"time": np.arange(4.0), "sensor": np.ones(4)})
    _raises(path, "missing required variable 'position'; variables found: 'time', 'sensor'")
    savemat(path, {"time": np.arange(4.0), "position": np.ones(4), "sensor": np.ones((2, 2))})
    _raises(path, "variable 'sensor': must be a row or column vector, got shape (2, 2)")
    savemat(path, {"time": np.arange(4.0), "position": ["a", "b", "c", "d"], "sensor": np.ones(4)})
    _raises(path, "variable 'position': not real numbers")
    savemat(path, {"time": np.arange(4.0), "position": np.ones(4), "sensor": [1, 2, np.inf, 4]})
    _raises(path, "variable 'sensor', sample 3: infinite value inf")
    path.write_bytes(b"definitely not a MATLAB file" * 10)
    _raises(path, "cannot read MATLAB file")


# --- writing -----------------------------------------------------------------------------


def test_write_refuses_overwrite_unless_forced(tmp_path: Path) -> None:
    rec = _recording(10)
    path = write_recording(rec, tmp_path / "deep" / "dir" / "out.csv")  # parents are created
    before = path.read_bytes()
    with pytest.raises(OutputExistsError, match=re.escape(f"{path} already exists; pass --force")):
        write_recording(_recording(10, seed=1), path)
    assert path.read_bytes() == before
    write_recording(_recording(10, seed=1), path, force=True)
    assert path.read_bytes() != before


def test_write_extra_columns_in_order(tmp_path: Path) -> None:
    rec = _recording(10)
    extra = {"zeta": np.arange(10), "alpha": rec.sensor * 2}
    path = write_recording(rec, tmp_path / "out.csv", extra=extra)
    frame = pd.read_csv(path)
    assert list(frame.columns) == ["time", "position", "sensor", "zeta", "alpha"]
    np.testing.assert_array_equal(frame["alpha"], rec.sensor * 2)
    assert read_recording(path).n_samples == 10  # extra columns are ignored on reading


@pytest.mark.parametrize(("extra", "match"), [({"x": np.zeros(9)}, "'x' has shape \\(9,\\)"),
                                              ({"sensor": np.zeros(10)}, "clashes")])
def test_write_rejects_bad_extra(tmp_path: Path, extra: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        write_recording(_recording(10), tmp_path / "out.csv", extra=extra)
    assert not (tmp_path / "out.csv").exists()


def test_write_rejects_unknown_suffix(tmp_path: Path) -> None:
    with pytest.raises(OutputError, match=r"written as \.csv, \.parquet or \.mat, not '\.txt'"):
        write_recording(_recording(10), tmp_path / "out.txt")
    assert list(tmp_path.iterdir()) == []


def test_write_json(tmp_path: Path) -> None:
    path = tmp_path / "sub" / "metrics.json"
    obj = {"rmse_mm": np.float64(0.25), "n": np.int64(3), "curve": np.array([1.0, 2.0])}
    assert write_json(obj, path) == path
    text = path.read_text(encoding="utf-8")
    assert json.loads(text) == {"rmse_mm": 0.25, "n": 3, "curve": [1.0, 2.0]}
    assert '\n  "n": 3' in text  # indented
    with pytest.raises(OutputExistsError, match=re.escape(f"{path} already exists; pass --force")):
        write_json({}, path)
    write_json({"a": 1}, path, force=True)
    assert json.loads(path.read_text(encoding="utf-8")) == {"a": 1}
    with pytest.raises(ValueError):
        write_json({"bad": float("nan")}, tmp_path / "nan.json")
    assert not (tmp_path / "nan.json").exists()
