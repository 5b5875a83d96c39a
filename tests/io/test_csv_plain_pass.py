"""The pandas-free CSV pass (issue 11.5): same bits as pandas' pass, and it steps aside for
anything that is not a plain decimal table."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from hystkit.io import Recording, _csv_reader, read_recording, write_recording
from hystkit.io._cells import Where


def _plain(path: Path, sep: str = ",", skip: int = 0) -> dict[str, np.ndarray] | None:
    return _csv_reader._read_plain(path, True, Where(str(path)), sep, skip, "")


def _pandas_pass(path: Path, sep: str = ",", skip: int = 0) -> dict[str, np.ndarray] | None:
    return _csv_reader._read_numbers(path, True, Where(str(path)), sep, skip)


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return np.array_equal(a.view(np.int64), b.view(np.int64))


def test_plain_pass_gives_pandas_bits_on_hard_floats(tmp_path):
    # Shortest round-trip reprs over 25 decades, subnormal-free, plus hand-written forms
    # (no leading digit, trailing point, explicit plus, upper-case exponent).
    rng = np.random.default_rng(11)
    n = 4000
    values = rng.standard_normal((n, 3)) * 10.0 ** rng.integers(-12, 13, (n, 3))
    lines = ["time,position,sensor"] + [",".join(repr(float(v)) for v in row) for row in values]
    lines += [".5,1.,+2E-3", "-.25,7,0.1e+2"]
    path = tmp_path / "hard.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    plain, reference = _plain(path), _pandas_pass(path)
    assert plain is not None and reference is not None
    for name in ("time", "position", "sensor"):
        assert _same_bits(plain[name], reference[name]), name
    assert plain["time"][:n].tolist() == values[:, 0].tolist()  # repr round trip


@pytest.mark.parametrize("sep", [",", ";", "\t"])
def test_written_recording_round_trips_through_the_plain_pass(tmp_path, sep):
    rng = np.random.default_rng(5)
    rec = Recording(time=np.arange(500) * 0.025, position=rng.standard_normal(500),
                    sensor=rng.standard_normal(500) * 1e-3)
    path = write_recording(rec, tmp_path / "rec.csv")
    if sep != ",":
        path.write_text(path.read_text(encoding="utf-8").replace(",", sep), encoding="utf-8")
    arrays = _plain(path, sep)
    assert arrays is not None
    for name in ("time", "position", "sensor"):
        assert _same_bits(arrays[name], getattr(rec, name)), name


@pytest.mark.parametrize("body, why", [
    ("1,2,3\n\n4,5,6\n", "a blank line"),
    ("1,2,3\n4,5\n", "a short row"),
    ("1,2,3\n4,5,6,7\n", "a long row"),
    ("1,2,3\r\n4,5,6\r\n", "CRLF line ends"),
    ('"1",2,3\n', "a quoted cell"),
    ("1,2,nan\n", "a literal nan"),
    ("1,2,1e999\n", "a number beyond float64"),
    ("1, 2,3\n", "a space in a cell"),
    ("1,2,1_000\n", "an underscore Python would accept"),
    ("0x1p3,2,3\n", "a hex float"),
])
def test_plain_pass_steps_aside(tmp_path, body, why):
    path = tmp_path / "odd.csv"
    path.write_text("time,position,sensor\n" + body, encoding="utf-8")
    assert _plain(path) is None, why


def test_plain_pass_steps_aside_for_a_quoted_header_and_large_files(tmp_path, monkeypatch):
    path = tmp_path / "q.csv"
    path.write_text('"time","position","sensor"\n0,2,3\n1,2,3\n2,2,3\n', encoding="utf-8")
    assert _plain(path) is None
    assert read_recording(path).n_samples == 3  # pandas' pass reads it
    path.write_text("time,position,sensor\n0,2,3\n1,2,3\n", encoding="utf-8")
    monkeypatch.setattr(_csv_reader, "PLAIN_BYTES", 10)
    assert _plain(path) is None


def test_plain_pass_honours_skipped_lines_and_extra_columns(tmp_path):
    path = tmp_path / "x.csv"
    path.write_text("sensor,extra,time,position\n1,9,0,5\n2,9,1,6\n3,9,2,7\n", encoding="utf-8")
    arrays = _plain(path, skip=1)
    assert arrays is not None
    assert arrays["time"].tolist() == [1.0, 2.0] and arrays["sensor"].tolist() == [2.0, 3.0]
    assert all(a.flags.c_contiguous for a in arrays.values())


def test_missing_column_is_the_same_error_in_both_passes(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("time,sensor\n0,1\n1,2\n", encoding="utf-8")
    messages = []
    for reader in (_plain, _pandas_pass):
        with pytest.raises(Exception) as info:
            reader(path)
        messages.append(str(info.value))
    assert messages[0] == messages[1] and "missing required column 'position'" in messages[0]


def test_reading_a_clean_csv_does_not_import_pandas(tmp_path):
    rec = Recording(time=np.arange(10.0), position=np.ones(10), sensor=np.arange(10.0))
    path = write_recording(rec, tmp_path / "rec.csv")
    code = ("import sys; from hystkit.io import read_recording; "
            f"r = read_recording({str(path)!r}); "
            "print(r.n_samples, 'pandas' in sys.modules, 'scipy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["10", "False", "False"]


def test_a_fit_of_a_clean_csv_loads_neither_pandas_nor_scipy_optimize(tmp_path):
    # issue 11.5: the start-up of 'hystkit fit' is what it imports; these two cost ~0.8 s
    rng = np.random.default_rng(0)
    t = np.arange(400) * 0.025
    u = np.sin(2 * np.pi * 0.5 * t)
    rec = Recording(time=t, position=3 * u, sensor=u + 0.01 * rng.standard_normal(t.size))
    path = write_recording(rec, tmp_path / "rec.csv")
    # neither the plain fit nor the prediction band's fold fits, which weight the samples (zero
    # on the held-out pieces) and run on the same solver, load them
    for options, loaded in ((["--no-band"], ["False", "False"]), ([], ["False", "False"])):
        model = tmp_path / f"m{len(options)}.json"
        code = ("import sys; from hystkit.cli import main; "
                f"code = main(['fit', {str(path)!r}, '--model', 'mpl', '--out', {str(model)!r}, "
                f"*{options!r}]); "
                "print(code, 'pandas' in sys.modules, 'scipy.optimize' in sys.modules)")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True)
        assert out.stdout.split()[-3:] == ["0", *loaded], out.stdout + out.stderr
        assert model.is_file()
