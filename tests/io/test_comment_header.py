"""A header written as a comment (issue 27.1): ``numpy.savetxt(..., header="time,position,
sensor")`` writes ``# time,position,sensor`` above the numbers; with no other header line
below it, that comment is the header, read by every CSV pass, by the other-columns reader,
by the commands and by ``stream --in``, and said once."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_array_equal

import hystkit as hk
from hystkit.cli import main
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.errors import InputError
from hystkit.io import ReadOptions, _csv_reader, csv_layout, read_recording
from hystkit.io._cells import Where
from hystkit.io._other_columns import read_other_columns
from hystkit.live import Stream
from hystkit.sensors import simulate_experiment


def _table(n: int = 120) -> np.ndarray:
    rng = np.random.default_rng(5)
    return np.column_stack([np.arange(n) * 0.025, rng.standard_normal(n),
                            100 + 1e-3 * rng.standard_normal(n), 20 + rng.random(n)])


def _savetxt(path: Path, table: np.ndarray, header: str, delimiter: str = ",",
             comments: str = "# ") -> Path:
    np.savetxt(path, table, delimiter=delimiter, header=header, comments=comments)
    return path


@pytest.mark.parametrize("header, delimiter, comments, preamble, notice", [
    ("time,position,sensor,temp", ",", "# ", 0, "the header read from the comment on line 1"),
    ("time;position;sensor;temp", ";", "#", 0,
     "semicolon-separated, the header read from the comment on line 1"),
    ("rig 3, gauge 7\ntime\tposition\tsensor\ttemp", "\t", "# ", 1,
     ("tab-separated, 1 comment line before the header skipped, the header read from the "
      "comment on line 2")),
])
def test_savetxt_header_is_the_header(tmp_path, header, delimiter, comments, preamble, notice):
    table = _table()
    path = _savetxt(tmp_path / "run.csv", table, header, delimiter, comments)
    layout = csv_layout(path)
    assert (layout.sep, layout.preamble, layout.comment_header) == (delimiter, preamble, True)
    assert layout.notice() == notice
    rec = read_recording(path)
    # savetxt's %.18e round-trips float64 exactly
    assert_array_equal(rec.time, table[:, 0])
    assert_array_equal(rec.position, table[:, 1])
    assert_array_equal(rec.sensor, table[:, 2])
    other = read_other_columns(path, rec.n_samples, ReadOptions())
    assert list(other) == ["temp"]
    assert_array_equal(other["temp"], table[:, 3])


def test_every_pass_reads_the_comment_header(tmp_path):
    table = _table()
    path = _savetxt(tmp_path / "run.csv", table, "time,position,sensor,temp")
    where = Where(str(path))
    for name in ("_read_plain", "_read_numbers", "_read_text"):
        arrays = getattr(_csv_reader, name)(path, True, where, ",", 0, "", comment_header=True)
        assert arrays is not None, name
        assert_array_equal(arrays["sensor"], table[:, 2])


def test_own_names_and_time_unit_in_a_comment_header(tmp_path):
    table = _table()
    table[:, 0] *= 1e3
    path = _savetxt(tmp_path / "run.csv", table[:, :3], "t_ms,x_mm,R_ohm")
    rec = hk.read(path, columns={"time": "t_ms", "position": "x_mm", "sensor": "R_ohm"},
                  time_unit="ms")
    assert rec.fs == pytest.approx(40.0, rel=1e-12)  # 25 ms steps in %.18e


def test_a_header_line_below_the_comments_stays_the_header(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text("# time,position,sensor\n# written by rig 3\nt,x,r\n0,1,2\n1,2,3\n")
    layout = csv_layout(path)
    assert (layout.preamble, layout.comment_header) == (2, False)
    rec = read_recording(path, options=ReadOptions(columns={"time": "t", "position": "x",
                                                            "sensor": "r"}))
    assert_array_equal(rec.sensor, [2.0, 3.0])


def test_a_comment_that_does_not_fit_the_data_is_no_header(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text("# exported by logger 4\n0,1,2\n1,2,3\n")
    assert not csv_layout(path).comment_header
    with pytest.raises(InputError, match=r"missing required column 'time'"):
        read_recording(path)


def test_units_row_below_a_comment_header(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text("# time;position;sensor\ns;mm;Ohm\n0;1,5;2\n1;2,5;3\n")
    rec = read_recording(path, options=ReadOptions(units_row=True))
    assert rec.units == (("position", "mm"), ("sensor", "Ohm"))
    assert_array_equal(rec.position, [1.5, 2.5])


def test_commands_read_and_say_the_comment_header(tmp_path, capsys):
    rec = simulate_experiment("noise", seed=1)
    path = _savetxt(tmp_path / "noise.csv", np.column_stack([rec.time, rec.position,
                                                             rec.sensor]),
                    "time,position,sensor")
    model = tmp_path / "model.json"
    capsys.readouterr()
    assert main(["fit", str(path), "--cells", "1", "--no-band", "--out", str(model)]) == 0
    out = capsys.readouterr().out
    assert f"reading {path}: the header read from the comment on line 1" in out
    assert f"{rec.n_samples} samples at 40 Hz" in out


def test_stream_in_reads_the_comment_header(tmp_path, capsys):
    comp = fit_compensator(simulate_experiment("noise", 1), 1, center="track", diagnose=False)
    model = save_compensator(comp, tmp_path / "noise.json")
    run = simulate_experiment("decay", 2)
    n = 40
    # position between time and sensor: read as the stream's second column, it would be
    # compensated as the sensor
    path = _savetxt(tmp_path / "run.csv", np.column_stack([run.time[:n], run.position[:n],
                                                           run.sensor[:n]]),
                    "time,position,sensor")
    capsys.readouterr()
    assert main(["stream", str(model), "--in", str(path)]) == 0
    captured = capsys.readouterr()
    rows = captured.out.splitlines()
    assert rows[0] == "time,position_estimate,flags"
    estimate = np.array([float(row.split(",")[1]) for row in rows[1:]])
    assert_array_equal(estimate, Stream(comp).process(run.sensor[:n]))
    assert "the header read from the comment on line 1" in captured.err
