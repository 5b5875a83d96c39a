"""Files as labs write them, read without options (issue 27.1): the separator, a decimal comma
and comment lines before the header are detected; what stays ambiguous is one error line naming
the file, the line and the option to pass; a given option still wins."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import hystkit as hk
from hystkit.errors import InputError
from hystkit.io import ReadOptions, Recording, _csv_layout, _csv_reader, csv_layout, read_recording
from hystkit.io._cells import Where
from hystkit.io._other_columns import read_other_columns

REAL = Path("/work/shared/data/piezo_actuator_150V_1Hz/hysteresis_v_150_1hz.csv")
OWN = {"time": "t_ms", "position": "x_mm", "sensor": "R_ohm"}


def _truth(n: int = 200) -> Recording:
    rng = np.random.default_rng(3)
    return Recording(time=np.arange(n) * 0.02, position=rng.standard_normal(n),
                     sensor=100 + rng.standard_normal(n) * 1e-3)


def _write(path: Path, rec: Recording, sep: str = ";", decimal: str = ",",
           preamble: str = "", line_end: str = "\n", bom: bool = False) -> Path:
    """`rec` with the user's names, time in ms, numbers as repr with `decimal`."""
    rows = [sep.join(OWN.values())]
    for t, p, s in zip(rec.time * 1e3, rec.position, rec.sensor):
        rows.append(sep.join(repr(float(v)).replace(".", decimal) for v in (t, p, s)))
    text = preamble + line_end.join(rows) + line_end
    path.write_bytes(("\ufeff" if bom else "").encode() + text.encode())
    return path


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return np.array_equal(np.asarray(a).view(np.int64), np.asarray(b).view(np.int64))


def _assert_read(back: Recording, rec: Recording) -> None:
    assert _same_bits(back.time, rec.time * 1e3 * 1e-3)  # read in ms, scaled as the reader does
    assert _same_bits(back.position, rec.position)
    assert _same_bits(back.sensor, rec.sensor)


@pytest.mark.parametrize("sep, decimal, preamble, line_end, bom", [
    (";", ",", "", "\n", False),                                   # Excel, most of Europe
    (";", ",", "", "\r\n", True),                                  # ... saved on Windows
    ("\t", ",", "", "\n", False),
    ("\t", ".", "", "\n", False),
    (";", ".", "", "\n", False),
    (",", ".", "", "\n", False),
    (";", ",", "# rig 3, gauge 7\n# 2026-11-30; operator A\n\n", "\n", False),
    (",", ".", "#logger v2.1\n", "\r\n", True),
])
def test_lab_layouts_read_without_options(tmp_path, sep, decimal, preamble, line_end, bom):
    rec = _truth()
    path = _write(tmp_path / "lab.csv", rec, sep, decimal, preamble, line_end, bom)
    options = ReadOptions(columns=OWN, time_unit="ms")
    _assert_read(read_recording(path, options=options), rec)
    _assert_read(hk.read(path, columns=OWN, time_unit="ms"), rec)  # the Python API alike
    layout = csv_layout(path, options)
    assert (layout.sep, layout.decimal, layout.preamble) == (
        sep, decimal, preamble.count("\n"))


def test_every_pass_reads_a_decimal_comma_to_the_same_bits(tmp_path):
    # shortest round-trip reprs over 25 decades: the pandas-free pass, pandas' C parser with
    # decimal=',' and the text pass must all give float()'s value of the dotted text
    rng = np.random.default_rng(11)
    values = rng.standard_normal((3000, 3)) * 10.0 ** rng.integers(-12, 13, (3000, 3))
    lines = ["# exported", "time;position;sensor"]
    lines += [";".join(repr(float(v)).replace(".", ",") for v in row) for row in values]
    path = tmp_path / "hard.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    where = Where(str(path))
    passes = {
        "plain": _csv_reader._read_plain(path, True, where, ";", 0, "", decimal=",",
                                         preamble=1),
        "pandas": _csv_reader._read_numbers(path, True, where, ";", 0, "", decimal=",",
                                            preamble=1),
        "text": _csv_reader._read_text(path, True, where, ";", 0, "", decimal=",", preamble=1),
    }
    for name, arrays in passes.items():
        assert arrays is not None, name
        for j, column in enumerate(("time", "position", "sensor")):
            assert _same_bits(arrays[column], values[:, j]), (name, column)


def test_a_real_recording_as_excel_in_europe_writes_it(tmp_path):
    # The piezo actuator run (5 kHz), the authors' fitting window, rewritten with ';', decimal
    # commas, time in ms and comment lines: read without options to the bits of the original.
    if not REAL.is_file():
        pytest.skip(f"{REAL} not available")
    rows = REAL.read_text(encoding="utf-8").splitlines()[35000:36000]
    cells = [row.split(",")[1:] for row in rows]  # col0 is empty: time [s], um, V
    t_ms = [repr(float(t) * 1e3) for t, _, _ in cells]
    path = tmp_path / "piezo.csv"
    lines = ["# SmartHysteresis piezo, 150 V 1 Hz", "# exported from the lab PC",
             "t_ms;disp_um;voltage_V"]
    lines += [f"{t};{d};{v}".replace(".", ",") for t, (_, d, v) in zip(t_ms, cells)]
    path.write_text("\r\n".join(lines) + "\r\n", encoding="utf-8-sig")
    columns = {"time": "t_ms", "position": "disp_um", "sensor": "voltage_V"}
    rec = hk.read(path, columns=columns, time_unit="ms")
    expected = np.array([[float(t) for t in t_ms], *[[float(c[k]) for c in cells]
                                                     for k in (1, 2)]])
    assert rec.n_samples == 1000
    assert _same_bits(rec.time, expected[0] * 1e-3)
    assert _same_bits(rec.position, expected[1])
    assert _same_bits(rec.sensor, expected[2])
    assert rec.fs == pytest.approx(5000, rel=1e-3)  # 0.2 ms steps, as the data's README says


def test_a_separator_that_cannot_be_told_is_one_line_naming_the_option(tmp_path):
    path = tmp_path / "odd.csv"
    path.write_text("# two kinds\ntime;position,sensor\n0;1,2\n1;2,3\n", encoding="utf-8")
    with pytest.raises(InputError) as err:
        read_recording(path)
    assert str(err.value) == (
        f"{path}: line 2: cannot tell the field separator: comma and semicolon each split the "
        "header and the 2 line(s) below it alike; pass --sep ',' or --sep ';' (or sep = "
        "\"...\" in the settings file)")
    # the given separator wins
    back = read_recording(path, need_position=False,
                          options=ReadOptions(sep=";", columns={"sensor": "position,sensor"}))
    np.testing.assert_array_equal(back.time, [0.0, 1.0])


def test_mixed_decimal_marks_are_refused_naming_a_line_of_each(tmp_path):
    path = tmp_path / "mixed.csv"
    path.write_text("time;position;sensor\n0;0,5;1\n1;1.5;2\n", encoding="utf-8")
    with pytest.raises(InputError) as err:
        read_recording(path)
    assert str(err.value) == (
        f"{path}: cannot tell the decimal mark: line 2 writes '0,5', line 3 '1.5'; pass "
        "--decimal ',' or --decimal '.' (or decimal = \",\" in the settings file)")
    assert "\n" not in str(err.value)


def test_a_decimal_comma_below_the_sample_or_against_the_option_says_what_to_pass(tmp_path):
    # integers beyond the bytes sampled, then a comma
    rows = [f"{k};{k};{k}" for k in range(8000)] + ["8000;0,5;1"]
    path = tmp_path / "late.csv"
    path.write_text("time;position;sensor\n" + "\n".join(rows) + "\n", encoding="utf-8")
    assert path.stat().st_size > _csv_layout.SAMPLE_BYTES
    with pytest.raises(InputError, match=r"column 'position', row 8001 \(line 8002\): "
                                         r"non-numeric value '0,5' \(a decimal comma\? pass "
                                         r"--decimal ','"):
        read_recording(path)
    assert read_recording(path, options=ReadOptions(decimal=",")).position[-1] == 0.5
    # a decimal comma read with decimal '.' on the first line: not mistaken for a units line
    path.write_text("time;position;sensor\n0,0;0,5;1,5\n0,1;0,6;1,6\n", encoding="utf-8")
    with pytest.raises(InputError) as err:
        read_recording(path, options=ReadOptions(decimal="."))
    assert "--decimal ','" in str(err.value) and "--units-row" not in str(err.value)


def test_a_point_where_the_file_uses_commas_is_named(tmp_path):
    rows = [f"{k},5;1,25;2" for k in range(6000)] + ["6000.5;1,25;2"]
    path = tmp_path / "eu.csv"
    path.write_text("time;position;sensor\n" + "\n".join(rows) + "\n", encoding="utf-8")
    assert path.stat().st_size > _csv_layout.SAMPLE_BYTES  # the point is beyond the sample
    with pytest.raises(InputError, match=r"column 'time', row 6001 \(line 6002\): non-numeric "
                                         r"value '6000.5' \(a decimal point"):
        read_recording(path)


def test_comment_lines_shift_every_line_number(tmp_path):
    head = "# one\n# two\ntime;position;sensor\n"
    path = tmp_path / "c.csv"
    path.write_text(head + "0;0,5;1\n0,1;0,6;x\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"column 'sensor', row 2 \(line 5\): non-numeric "
                                         "value 'x'"):
        read_recording(path)
    path.write_text(head + "0;0,5;1\n0,1;0,6;1;7\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"row 2 \(line 5\): 4 fields but the header names 3"):
        read_recording(path)
    path.write_text("# one\n# two\n", encoding="utf-8")
    with pytest.raises(InputError, match="line 2: only comment lines, no header"):
        read_recording(path)
    path.write_text("# one\n0,1,2\n1,2,3\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"\(line 2, below the comments, must be a "
                                         "comma-separated header"):
        read_recording(path)


def test_units_line_below_comments_with_decimal_commas(tmp_path):
    path = tmp_path / "u.csv"
    path.write_text("# rig\nt_ms;x_mm;R_ohm;temp\nms;mm;Ohm;degC\n0;0,5;100,5;20,5\n"
                    "20;0,75;100,25;20,75\n", encoding="utf-8")
    options = ReadOptions(columns=OWN, time_unit="ms", units_row=True)
    rec = read_recording(path, options=options)
    assert rec.units == (("position", "mm"), ("sensor", "Ohm"))
    np.testing.assert_array_equal(rec.position, [0.5, 0.75])
    others = read_other_columns(path, rec.n_samples, options)  # compensate keeps them
    np.testing.assert_array_equal(others["temp"], [20.5, 20.75])
    path.write_text("# rig\nt_ms;x_mm;R_ohm\n0;0,5;100,5\n20;0,75;100,25\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"line 3: --units-row reads units there but it "
                                         r"holds numbers \(0, 0,5, 100,5\)"):
        read_recording(path, options=options)


def test_the_settings_file_may_give_the_decimal_mark(tmp_path):
    rows = [f"{k};{k};{k}" for k in range(8000)] + ["8000;0,5;1"]
    path = tmp_path / "late.csv"
    path.write_text("time;position;sensor\n" + "\n".join(rows) + "\n", encoding="utf-8")
    (tmp_path / "late.toml").write_text('decimal = ","\nsep = ";"\n', encoding="utf-8")
    assert hk.read(path).position[-1] == 0.5
    (tmp_path / "late.toml").write_text('decimal = ";"\n', encoding="utf-8")
    with pytest.raises(InputError, match=r"late.toml: decimal must be one of '.', ',', 'auto'"):
        hk.read(path)


def test_notice_says_only_what_a_plain_file_would_not_have(tmp_path):
    rec = _truth(20)
    plain = _write(tmp_path / "plain.csv", rec, ",", ".")
    assert csv_layout(plain).notice() == ""
    eu = _write(tmp_path / "eu.csv", rec, ";", ",", "# a\n# b\n")
    assert csv_layout(eu).notice() == ("semicolon-separated, decimal comma, 2 comment lines "
                                       "before the header skipped")
    given = csv_layout(eu, ReadOptions(sep=";", decimal=","))
    assert (given.sep, given.decimal, given.detected) == (";", ",", ("preamble",))
