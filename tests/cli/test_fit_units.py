"""``hystkit fit`` on several files in different units is refused before the fit, in one line
naming the file (fitting them jointly would mix scales); pieces of one file (``--gaps split``)
share its units and fit."""

from __future__ import annotations

import numpy as np

from tests.cli_support import run_cli


def _write(path, position_unit: str, gap: bool = False) -> None:
    t = np.arange(2400) / 40.0
    if gap:
        t[1200:] += 5.0  # a 5 s gap: two pieces
    x = 2.0 * np.sin(2 * np.pi * 0.2 * t)
    sensor = 1.0 + 0.3 * x + 0.02 * np.tanh(5 * np.gradient(x))
    with open(path, "w") as out:
        out.write(f"time,position,sensor\ns,{position_unit},V\n")
        out.writelines(",".join(f"{v:.9g}" for v in row) + "\n" for row in zip(t, x, sensor, strict=True))


def test_files_in_different_units_are_refused_in_one_line(tmp_path, capsys):
    _write(tmp_path / "a.csv", "mm")
    _write(tmp_path / "b.csv", "um")
    code, _, err = run_cli(capsys, "fit", tmp_path / "a.csv", tmp_path / "b.csv", "--units-row",
                           "--model", "mpl", "--out", tmp_path / "m.json")
    assert code == 2
    assert err.count("\n") == 1
    assert "b.csv: position is in 'um', an earlier recording's in 'mm'" in err
    assert not (tmp_path / "m.json").exists()


def test_pieces_of_one_file_share_its_units(tmp_path, capsys):
    _write(tmp_path / "gap.csv", "mm", gap=True)
    code, out, err = run_cli(capsys, "fit", tmp_path / "gap.csv", "--units-row", "--gaps",
                             "split", "--model", "mpl", "--no-band", "--out",
                             tmp_path / "m.json")
    assert code in (0, 3), err
    assert (tmp_path / "m.json").exists()
    assert "position [mm]" in out
