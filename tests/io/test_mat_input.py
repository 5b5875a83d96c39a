"""``.mat`` input as MATLAB users save it: structs, tables as struct, matrices (issue 11).

Every file is written by `scipy.io.savemat` the way MATLAB lays it out (a struct is a dict, a
table saved with ``table2struct(T, 'ToScalar', true)`` is a struct of column vectors, a matrix
has one sample per row); the values read must equal the arrays written, bit for bit.
"""

from __future__ import annotations

import re
import shutil
import subprocess

import h5py
import numpy as np
import pytest
from numpy.testing import assert_array_equal
from scipy.io import savemat

from hystkit.cli import main
from hystkit.errors import InputError
from hystkit.io import ReadOptions, read_recording

N = 200
T = np.arange(N) / 100.0
X = np.sin(2 * np.pi * T)
Y = 0.1 * np.cos(2 * np.pi * T) + 1e-3 * X


def _same(rec, *, position: bool = True) -> None:
    assert_array_equal(rec.time, T)
    assert_array_equal(rec.sensor, Y)
    if position:
        assert_array_equal(rec.position, X)
    else:
        assert rec.position is None


def _message(path, options=None, **kw) -> str:
    with pytest.raises(InputError) as info:
        read_recording(path, options=options, **kw)
    text = str(info.value)
    assert "\n" not in text and text.startswith(str(path))
    return text


def test_struct_is_found_without_mat_var(tmp_path):
    path = tmp_path / "s.mat"
    savemat(path, {"s": {"time": T, "position": X, "sensor": Y}})
    _same(read_recording(path))


def test_table_saved_as_struct_with_own_names(tmp_path):
    # table2struct(T, 'ToScalar', true): one field per table column, column vectors, and
    # other columns (text as a cell array) beside them
    path = tmp_path / "table.mat"
    notes = np.array([f"n{i}" for i in range(N)], dtype=object).reshape(-1, 1)
    savemat(path, {"T": {"t_ms": T * 1e3, "displacement_mm": X, "resistance_ohm": Y,
                         "notes": notes}}, oned_as="column")
    options = ReadOptions(columns={"time": "t_ms", "position": "displacement_mm",
                                   "sensor": "resistance_ohm"}, time_unit="ms")
    rec = read_recording(path, options=options)
    np.testing.assert_allclose(rec.time, T, rtol=0, atol=1e-15)  # ms -> s: one rounding
    assert_array_equal(rec.position, X)
    assert_array_equal(rec.sensor, Y)


def test_matrix_n_by_3_and_n_by_2(tmp_path):
    path = tmp_path / "m.mat"
    savemat(path, {"M": np.column_stack([T, X, Y])})
    _same(read_recording(path))
    path2 = tmp_path / "m2.mat"
    savemat(path2, {"M": np.column_stack([T, Y])})
    _same(read_recording(path2, need_position=False), position=False)
    assert "no column given for position" in _message(path2)


def test_matrix_columns_are_one_based(tmp_path):
    path = tmp_path / "wide.mat"
    savemat(path, {"data": np.column_stack([np.zeros(N), T, Y, X, np.ones(N)])})
    assert "with 5 columns, say which are which" in _message(path)
    options = ReadOptions(columns={"time": "2", "position": "4", "sensor": "3"})
    _same(read_recording(path, options=options))
    bad = ReadOptions(columns={"time": "2", "position": "6", "sensor": "3"})
    assert "column 6 (position) does not exist; columns are numbered 1 to 5" in \
        _message(path, bad)
    named = ReadOptions(columns={"time": "t"})
    assert "gives column numbers for a matrix" in _message(path, named)


def test_mat_var_chooses_among_several(tmp_path):
    path = tmp_path / "two.mat"
    savemat(path, {"run1": {"time": T, "position": X, "sensor": Y},
                   "run2": {"time": T, "position": -X, "sensor": -Y},
                   "M": np.column_stack([T, X, Y])})
    text = _message(path)
    for part in ("'run1' (struct with fields time, position, sensor)", "'M' (double 200x3)",
                 "--mat-var"):
        assert part in text, text
    rec = read_recording(path, options=ReadOptions(mat_var="run2"))
    assert_array_equal(rec.position, -X)
    assert "no variable 'run3' (--mat-var)" in _message(path, ReadOptions(mat_var="run3"))


def test_struct_with_a_missing_field_names_struct_and_fields(tmp_path):
    path = tmp_path / "s.mat"
    savemat(path, {"s": {"time": T, "pos": X, "sensor": Y}})
    text = _message(path)
    assert re.search(r"struct 's': missing required field 'position'; fields found: 'time', "
                     r"'pos', 'sensor'", text), text


def test_struct_array_and_text_are_one_line(tmp_path):
    path = tmp_path / "sa.mat"
    rows = np.zeros((N, 1), dtype=[("time", "O"), ("position", "O"), ("sensor", "O")])
    for i in range(N):
        rows[i, 0] = (T[i], X[i], Y[i])
    savemat(path, {"S": rows, "label": "run 1"})
    assert "struct array; save one struct of column vectors" in \
        _message(path, ReadOptions(mat_var="S"))
    assert "holds text, not a recording" in _message(path, ReadOptions(mat_var="label"))


def test_row_major_matrix_is_refused_with_the_fix(tmp_path):
    path = tmp_path / "rows.mat"
    savemat(path, {"M": np.vstack([T, X, Y])})
    assert "one sample per row is expected; transpose it" in \
        _message(path, ReadOptions(mat_var="M"))


def test_v73_hdf5_file_is_one_clear_line(tmp_path):
    path = tmp_path / "v73.mat"
    with h5py.File(path, "w", userblock_size=512) as f:
        f["time"], f["position"], f["sensor"] = T, X, Y
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(116) + b"\0" * 8 + b"\x00\x02IM"
    with path.open("r+b") as f:
        f.write(header)
    assert "MATLAB v7.3 (HDF5) files are not supported; save with '-v7'" in _message(path)


def test_cli_fit_reads_a_struct_by_mat_var(tmp_path, capsys):
    rec_csv = tmp_path / "rec.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(rec_csv)]) == 0
    rec = read_recording(rec_csv)
    path = tmp_path / "own.mat"
    savemat(path, {"meta": "bench 2", "run": {"t": rec.time, "x_mm": rec.position,
                                              "r": rec.sensor}}, oned_as="column")
    columns = "time=t,position=x_mm,sensor=r"
    code = main(["fit", str(path), "--mat-var", "run", "--columns", columns, "--cells", "1",
                 "--out", str(tmp_path / "m.json")])
    assert code == 0, capsys.readouterr().err
    code = main(["fit", str(path), "--mat-var", "1run", "--out", str(tmp_path / "n.json")])
    err = capsys.readouterr().err
    assert code == 2 and "MATLAB variable name" in err


@pytest.mark.skipif(shutil.which("octave") is None, reason="octave is not installed")
def test_files_saved_by_octave(tmp_path):
    # an independent writer of MATLAB files: a struct and an N x 3 matrix saved with -v7
    path = tmp_path / "oct.mat"
    script = ("t = (0:199)' / 100; s.time = t; s.position = sin(2*pi*t); "
              "s.sensor = cos(2*pi*t); M = [t, s.position, s.sensor]; "
              f"save('-v7', '{path}', 's', 'M');")
    subprocess.run(["octave", "--no-gui", "--quiet", "--eval", script], capture_output=True,
                   timeout=120, check=False)
    assert path.exists()
    for var in ("s", "M"):
        rec = read_recording(path, options=ReadOptions(mat_var=var))
        assert_array_equal(rec.time, T)  # (0:199)/100: the same IEEE divisions
        # Octave's and numpy's sin/cos may differ by an ulp
        np.testing.assert_allclose(rec.position, np.sin(2 * np.pi * T), rtol=0, atol=1e-15)
        np.testing.assert_allclose(rec.sensor, np.cos(2 * np.pi * T), rtol=0, atol=1e-15)
    text = _message(path)
    assert "'s' (struct with fields time, position, sensor)" in text
    assert "'M' (double 200x3)" in text
