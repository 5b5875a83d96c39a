"""Reading a user's own files: column names, time units, separators, skipped lines (issue 11.1)."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
import scipy.io

from hystkit.errors import InputError
from hystkit.io import ReadOptions, Recording, read_recording, write_recording

N = 50
OWN = {"time": "t_ms", "position": "displacement_mm", "sensor": "resistance_ohm"}


def _truth() -> Recording:
    t = np.arange(N) * 0.002
    return Recording(time=t, position=np.sin(40 * t), sensor=0.01 * np.cos(40 * t) + 0.1)


def _own_csv(path, rec: Recording, sep: str = ";", units_row: bool = False, scale=1e3,
             names=OWN):
    """`rec` as a user would save it: own names, time in ms, `sep` between fields."""
    lines = [sep.join(names.values())] + ([sep.join(["ms", "mm", "Ohm"])] if units_row else [])
    lines += [sep.join(repr(float(v)) for v in (t * scale, p, s))
              for t, p, s in zip(rec.time, rec.position, rec.sensor)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _assert_same(back: Recording, rec: Recording) -> None:
    np.testing.assert_allclose(back.time, rec.time, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(back.position, rec.position)
    np.testing.assert_array_equal(back.sensor, rec.sensor)


@pytest.mark.parametrize("sep, given", [(";", ";"), ("\t", "tab"), ("\t", "\\t"), (",", ","),
                                        (";", "auto"), ("\t", "auto")])
def test_own_names_ms_and_separators(tmp_path, sep, given):
    rec = _truth()
    path = _own_csv(tmp_path / "own.csv", rec, sep=sep)
    back = read_recording(path, options=ReadOptions(columns=OWN, time_unit="ms", sep=given))
    _assert_same(back, rec)


@pytest.mark.parametrize("unit, scale", [("us", 1e6), ("ns", 1e9), ("min", 1 / 60)])
def test_time_units_become_seconds(tmp_path, unit, scale):
    rec = _truth()
    names = {**OWN, "time": f"t_{unit}"}
    path = _own_csv(tmp_path / "own.csv", rec, scale=scale, names=names)
    back = read_recording(path, options=ReadOptions(columns=names, time_unit=unit, sep=";"))
    _assert_same(back, rec)


@pytest.mark.parametrize("name, unit", [("t_ms", "ms"), ("time [us]", "us"), ("time_s", "s"),
                                        ("Zeit (µs)", "us")])
def test_a_time_column_named_for_another_unit_is_refused(tmp_path, name, unit):
    """Forgetting --time-unit ms on a column named t_ms read 12000 samples at 0.05 Hz without
    a word (issue 27): the name contradicts the unit read, so the file is refused with the fix."""
    rec = _truth()
    names = {**OWN, "time": name}
    path = _own_csv(tmp_path / "own.csv", rec, names=names)
    other = "ms" if unit != "ms" else "s"
    with pytest.raises(InputError, match=rf"the time column '{re.escape(name)}' is named for "
                                         rf"{unit} but time is read in {other}; pass "
                                         rf"--time-unit {unit}"):
        read_recording(path, options=ReadOptions(columns=names, time_unit=other, sep=";"))
    back = read_recording(path, options=ReadOptions(columns=names, time_unit=unit, sep=";"))
    assert back.n_samples == N


def test_skip_rows_skips_a_units_line_and_keeps_line_numbers(tmp_path):
    rec = _truth()
    path = _own_csv(tmp_path / "own.csv", rec, units_row=True)
    options = ReadOptions(columns=OWN, time_unit="ms", sep=";", skip_rows=1)
    _assert_same(read_recording(path, options=options), rec)
    with pytest.raises(InputError, match=r"'t_ms' \(time\), row 1 \(line 2\): non-numeric "
                                         r"value 'ms'"):
        read_recording(path, options=ReadOptions(columns=OWN, time_unit="ms", sep=";"))
    lines = path.read_text().splitlines()
    lines[13] = lines[13].replace(";", ";x;", 1)  # data row 12 on line 14: an extra field
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"row 12 \(line 14\): 4 fields"):
        read_recording(path, options=options)


def test_errors_name_the_users_column(tmp_path):
    rec = _truth()
    path = _own_csv(tmp_path / "own.csv", rec, units_row=True)
    lines = path.read_text().splitlines()
    fields = lines[13].split(";")
    lines[13] = ";".join([fields[0], "x", fields[2]])  # data row 12, line 14
    path.write_text("\n".join(lines) + "\n")
    options = ReadOptions(columns=OWN, time_unit="ms", sep=";", skip_rows=1)
    with pytest.raises(InputError) as err:
        read_recording(path, options=options)
    assert str(err.value) == (f"{path}: column 'displacement_mm' (position), row 12 (line 14): "
                              "non-numeric value 'x'")
    missing = ReadOptions(columns={**OWN, "sensor": "R_ohm"}, time_unit="ms", sep=";",
                          skip_rows=1)
    with pytest.raises(InputError, match=r"missing required column 'R_ohm' \(sensor\); columns "
                                         r"found: 't_ms', 'displacement_mm', 'resistance_ohm'"):
        read_recording(path, options=missing)


def test_checks_after_reading_name_the_users_column(tmp_path):
    rec = _truth()
    path = _own_csv(tmp_path / "own.csv", rec)
    lines = path.read_text().splitlines()
    lines[5] = lines[4]  # a repeated time stamp
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"column 't_ms' \(time\), row 5 \(line 6\): time is "
                                         r"not strictly increasing"):
        read_recording(path, options=ReadOptions(columns=OWN, time_unit="ms", sep=";"))


def test_defaults_read_as_before(tmp_path):
    rec = _truth()
    path = write_recording(rec, tmp_path / "std.csv")
    default = read_recording(path)
    explicit = read_recording(path, options=ReadOptions())
    for name in ("time", "position", "sensor"):
        np.testing.assert_array_equal(getattr(explicit, name), getattr(rec, name))
        np.testing.assert_array_equal(getattr(default, name), getattr(rec, name))
    (tmp_path / "semi.csv").write_text("time;position;sensor\n0;1;2\n1;2;3\n")
    # the separator is detected by default (issue 27.1), and a given one still wins
    np.testing.assert_array_equal(read_recording(tmp_path / "semi.csv").sensor, [2.0, 3.0])
    with pytest.raises(InputError, match="comma-separated header"):
        read_recording(tmp_path / "semi.csv", options=ReadOptions(sep=","))


def test_mat_variables_mapped(tmp_path):
    rec = _truth()
    path = tmp_path / "own.mat"
    scipy.io.savemat(path, {"t_ms": rec.time * 1e3, "displacement_mm": rec.position,
                            "resistance_ohm": rec.sensor, "time": np.zeros(3)})
    back = read_recording(path, options=ReadOptions(columns=OWN, time_unit="ms"))
    _assert_same(back, rec)
    scipy.io.savemat(path, {"t_ms": rec.time * 1e3, "displacement_mm": rec.position,
                            "resistance_ohm": rec.sensor.astype(complex)})
    with pytest.raises(InputError, match=r"variable 'resistance_ohm' \(sensor\): not real"):
        read_recording(path, options=ReadOptions(columns=OWN, time_unit="ms"))


def test_parquet_columns_mapped(tmp_path):
    rec = _truth()
    path = tmp_path / "own.parquet"
    frame = pd.DataFrame({"t_ms": rec.time * 1e3, "displacement_mm": rec.position,
                          "resistance_ohm": rec.sensor})
    frame.to_parquet(path)
    _assert_same(read_recording(path, options=ReadOptions(columns=OWN, time_unit="ms")), rec)
    frame["displacement_mm"] = frame["displacement_mm"].astype(str)
    frame.loc[7, "displacement_mm"] = "x"
    frame.to_parquet(path)
    with pytest.raises(InputError, match=r"column 'displacement_mm' \(position\), row 8: "
                                         r"non-numeric value 'x'"):
        read_recording(path, options=ReadOptions(columns=OWN, time_unit="ms"))


def test_partial_mapping_keeps_the_other_names(tmp_path):
    rec = _truth()
    path = tmp_path / "part.csv"
    pd.DataFrame({"time": rec.time, "pos": rec.position, "sensor": rec.sensor}).to_csv(
        path, index=False, float_format="%.17g")
    options = ReadOptions(columns={"position": "pos"})
    assert options.columns == (("position", "pos"),)
    _assert_same(read_recording(path, options=options), rec)


@pytest.mark.parametrize("kwargs, message", [
    ({"columns": {"pos": "x"}}, "unknown name 'pos'"),
    ({"columns": {"time": ""}}, "time needs a column name"),
    ({"columns": {"time": "a", "sensor": "a"}}, "time and sensor would both be read from column 'a'"),
    ({"columns": {"position": "time"}}, "time and position would both"),
    ({"columns": {"position": "sensor", "sensor": "position"}},
     "position would be read from column 'sensor' and sensor from column 'position'"),
    ({"columns": {"position": "Sensor", "sensor": "POSITION"}}, "columns crossed"),
    ({"time_unit": "h"}, "time_unit must be one of s, ms, us, ns, min"),
    ({"skip_rows": -1}, "skip_rows must be a whole number"),
    ({"skip_rows": True}, "skip_rows must be a whole number"),
    ({"sep": "|"}, "sep must be one of"),
])
def test_bad_settings_are_one_line(kwargs, message):
    with pytest.raises(ValueError, match=message) as err:
        ReadOptions(**kwargs)
    assert "\n" not in str(err.value)


def test_a_lab_column_named_sensor_may_be_the_position():
    """Only the full cross of hystkit's two names is refused (issue 24): a lab may call its
    reference instrument 'sensor' and the device it calibrates something else."""
    options = ReadOptions(columns={"position": "sensor", "sensor": "gauge"})
    assert options.columns == (("position", "sensor"), ("sensor", "gauge"))


def test_options_are_frozen_and_normalised():
    options = ReadOptions(columns={"sensor": "R", "time": "t", "position": "position"},
                          sep="tab")
    assert options.columns == (("time", "t"), ("sensor", "R"))  # hystkit's order, no identity
    assert options.sep == "\t"
    assert options == ReadOptions(columns=(("time", "t"), ("sensor", "R")), sep="\t")
    with pytest.raises(AttributeError):
        options.time_unit = "ms"
