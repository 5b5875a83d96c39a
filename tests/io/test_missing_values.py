"""Rows missing a value (issue 27.1): ``missing = "error"`` (the default) refuses the file at
the first such row, counting them and naming the option; ``drop`` leaves them out;
``interpolate`` fills them linearly in time. The rows touched are said in one line, later
errors still name the file's rows, and the other columns follow the rows kept."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import hystkit as hk
from hystkit.errors import InputError
from hystkit.io import ReadOptions, read_recording, read_recording_config
from hystkit.io._cells import Where
from hystkit.io._missing import fill_missing
from hystkit.io._other_columns import read_other_columns

N = 200
DT = 0.025


def _run() -> dict[str, np.ndarray]:
    t = np.arange(N) * DT
    return {"time": t, "position": np.sin(2 * np.pi * 0.5 * t),
            "sensor": 100 + 0.1 * np.sin(2 * np.pi * 0.5 * t - 0.3)}


def _write(path: Path, holes: dict[str, list[int]], sep: str = ",", decimal: str = ".") -> Path:
    """The run with empty cells at `holes` (column -> rows from 0) and a temperature column."""
    run = _run()
    lines = [sep.join(["time", "position", "sensor", "temp"])]
    for i in range(N):
        cells = ["" if i in holes.get(name, ()) else repr(float(run[name][i])).replace(
            ".", decimal) for name in ("time", "position", "sensor")]
        lines.append(sep.join([*cells, str(i)]))
    path.write_text("\n".join(lines) + "\n")
    return path


HOLES = {"position": [10, 30], "sensor": [50], "time": [120]}  # 4 rows, all inside


def test_default_refuses_counting_the_rows_and_naming_the_option(tmp_path):
    path = _write(tmp_path / "holes.csv", HOLES)
    with pytest.raises(InputError) as err:
        read_recording(path)
    assert str(err.value) == (
        f"{path}: column 'time', row 121 (line 122): empty cell (4 rows miss a value; "
        "--missing interpolate or --missing drop reads past them, or missing = "
        "\"interpolate\" in the settings file)")


def test_interpolate_fills_linearly_in_time_and_says_so(tmp_path, capsys):
    path = _write(tmp_path / "holes.csv", HOLES)
    capsys.readouterr()
    rec = read_recording(path, options=ReadOptions(missing="interpolate"))
    err = capsys.readouterr().err
    assert err == (f"hystkit: {path}: 4 of {N} rows miss a value: 4 interpolated linearly in "
                   "time (row 11 (line 12), row 31 (line 32), row 51 (line 52) and 1 more)\n")
    run = _run()
    assert rec.n_samples == N
    untouched = np.setdiff1d(np.arange(N), [10, 30, 50, 120])
    assert_array_equal(rec.position[untouched], run["position"][untouched])
    # a missing time, by its place on the uniform grid: t[119] + DT to rounding
    assert_allclose(rec.time[120], run["time"][120], rtol=0, atol=1e-15)
    # linear between the neighbours: the mean of the two, to rounding
    for name, i in (("position", 10), ("position", 30), ("sensor", 50)):
        assert_allclose(getattr(rec, name)[i], (run[name][i - 1] + run[name][i + 1]) / 2,
                        rtol=1e-15, atol=1e-15)


def test_drop_leaves_rows_out_and_later_errors_name_the_files_rows(tmp_path, capsys):
    path = _write(tmp_path / "holes.csv", HOLES)
    capsys.readouterr()
    with pytest.raises(InputError) as err:  # dropped rows leave gaps: not uniform
        read_recording(path, options=ReadOptions(missing="drop"))
    assert str(err.value).startswith(f"{path}: column 'time', row 12 (line 13): non-uniform "
                                     "sampling: step 0.05 s")
    assert capsys.readouterr().err == (
        f"hystkit: {path}: 4 of {N} rows miss a value: 4 dropped (row 11 (line 12), row 31 "
        "(line 32), row 51 (line 52) and 1 more); the time steps over them are gaps "
        "(--missing interpolate keeps the time grid)\n")
    rec = read_recording(path, options=ReadOptions(missing="drop", resample_hz=40.0))
    assert rec.n_samples == N and rec.fs == pytest.approx(40.0)


def test_rows_at_the_ends_are_dropped_by_both(tmp_path, capsys):
    path = _write(tmp_path / "ends.csv", {"sensor": [0, 1], "position": [N - 1]})
    for mode in ("drop", "interpolate"):
        capsys.readouterr()
        rec = read_recording(path, options=ReadOptions(missing=mode))
        assert_array_equal(rec.time, _run()["time"][2:N - 1])  # uniform still: no gap inside
        said = capsys.readouterr().err
        assert f"3 of {N} rows miss a value: 3 dropped" in said
        assert "gaps" not in said
    other = read_other_columns(path, N - 3, ReadOptions(missing="interpolate"))
    assert_array_equal(other["temp"], np.arange(2, N - 1))


def test_other_columns_follow_the_rows_kept(tmp_path):
    path = _write(tmp_path / "holes.csv", {"sensor": [0], "position": [N - 2, N - 1]})
    options = ReadOptions(missing="drop")
    rec = read_recording(path, options=options)
    other = read_other_columns(path, rec.n_samples, options)
    assert_array_equal(other["temp"], np.arange(1, N - 2))


def test_decimal_comma_file_and_hk_read(tmp_path, capsys):
    path = _write(tmp_path / "eu.csv", {"sensor": [7]}, sep=";", decimal=",")
    capsys.readouterr()
    rec = hk.read(path, missing="interpolate")
    assert rec.n_samples == N
    assert "1 of 200 rows misses a value: 1 interpolated" in capsys.readouterr().err


def test_nan_cells_and_mat_files_alike(tmp_path, capsys):
    from scipy.io import savemat

    run = _run()
    run["sensor"][[5, 6]] = np.nan
    path = tmp_path / "run.mat"
    savemat(path, run, oned_as="column")
    with pytest.raises(InputError, match=r"variable 'sensor', sample 6: missing or NaN value "
                                         r"\(2 rows miss a value; --missing interpolate"):
        read_recording(path)
    capsys.readouterr()
    rec = read_recording(path, options=ReadOptions(missing="interpolate"))
    assert np.isfinite(rec.sensor).all()
    assert "2 of 200 rows miss a value: 2 interpolated linearly in time (sample 6, sample 7)" \
        in capsys.readouterr().err


def test_settings_file_key(tmp_path, capsys):
    path = _write(tmp_path / "holes.csv", HOLES)
    settings = path.with_suffix(".toml")
    settings.write_text('missing = "interpolate"\n')
    assert read_recording_config(settings) == {"missing": "interpolate"}
    capsys.readouterr()
    assert hk.read(path).n_samples == N
    err = capsys.readouterr().err
    assert f"with the settings in {settings}" in err and "4 interpolated" in err
    settings.write_text('missing = "guess"\n')
    with pytest.raises(InputError, match="missing must be one of error, drop, interpolate"):
        read_recording_config(settings)


def test_bad_option_is_one_line():
    with pytest.raises(ValueError, match="missing must be one of error, drop, interpolate, "
                                         "got 'fill'"):
        ReadOptions(missing="fill")


def test_fill_missing_leaves_complete_data_alone():
    run = _run()
    out, where, notice = fill_missing(dict(run), Where("x.csv"), "interpolate")
    assert notice == ""
    assert all(out[name] is not run[name] or np.array_equal(out[name], run[name])
               for name in run)
    assert_array_equal(where.rows, np.arange(N))
    assert fill_missing(dict(run), Where("x.csv"), "error")[2] == ""
