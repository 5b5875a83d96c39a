"""A recording with time gaps (issue 27.1): refused by default naming the gap's row and the
option; ``gaps = "split"`` (``--gaps split``, a settings-file key) reads the pieces between
gaps, says how many and where in one line, and the pieces are fitted jointly as several
recordings are (``hk.fit``; the CLI's ``Reader.training_files``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_array_equal

import hystkit as hk
from hystkit.cli import main
from hystkit.cli._common import Parser, add_read_options
from hystkit.cli._read_args import given_read_options
from hystkit.cli._reading import Reader
from hystkit.compensation import fit_compensator
from hystkit.errors import InputError
from hystkit.io import ReadOptions, read_pieces, read_recording, read_recording_config, time_gaps
from hystkit.sensors import simulate_experiment

CUTS = (3000, 6000)  # rows (from 0) after which the logger paused
PAUSES = (3.0, 0.5)  # [s]


def _gapped(path: Path, rec=None) -> Path:
    rec = simulate_experiment("noise", seed=1) if rec is None else rec
    time = rec.time.copy()
    for cut, pause in zip(CUTS, PAUSES):
        time[cut:] += pause
    frame = pd.DataFrame({"time": time, "position": rec.position, "sensor": rec.sensor,
                          "temp": np.arange(rec.n_samples)})
    frame.to_csv(path, index=False, float_format="%.17g")
    return path


def test_default_refuses_naming_the_gaps_row_and_the_option(tmp_path):
    path = _gapped(tmp_path / "run.csv")
    with pytest.raises(InputError) as err:
        read_recording(path)
    assert str(err.value) == (
        f"{path}: column 'time', row 3001 (line 3002): non-uniform sampling: step 3.025 s "
        "deviates more than 1% from the median step 0.025 s; a time gap: split the recording "
        "there, or read the pieces between gaps with --gaps split to fit them jointly")


def test_split_reads_the_pieces_and_says_where(tmp_path, capsys):
    rec = simulate_experiment("noise", seed=1)
    path = _gapped(tmp_path / "run.csv", rec)
    capsys.readouterr()
    pieces = read_pieces(path)
    assert capsys.readouterr().err == (
        f"hystkit: {path}: 2 time gaps, read as 3 pieces fitted jointly: rows 1-3000, "
        "3001-6000, 6001-8000 (gaps of 3.025 s after 74.975 s, 0.525 s after 152.975 s)\n")
    assert [p.source for p in pieces] == [f"{path} (piece {k} of 3)" for k in (1, 2, 3)]
    bounds = (0, *CUTS, rec.n_samples)
    for piece, start, stop in zip(pieces, bounds[:-1], bounds[1:]):
        assert_array_equal(piece.sensor, rec.sensor[start:stop])
        assert_array_equal(piece.position, rec.position[start:stop])
        assert piece.fs == pytest.approx(40.0, rel=1e-9)


def test_a_file_without_gaps_is_one_piece_unsaid(tmp_path, capsys):
    rec = simulate_experiment("noise", seed=1)
    path = tmp_path / "plain.csv"
    rec.to_frame().to_csv(path, index=False, float_format="%.17g")
    capsys.readouterr()
    pieces = read_pieces(path)
    assert len(pieces) == 1 and pieces[0].source == str(path)
    assert capsys.readouterr().err == ""
    assert read_recording(path, options=ReadOptions(gaps="split")).n_samples == rec.n_samples


def test_a_command_reading_one_recording_refuses_the_pieces(tmp_path):
    path = _gapped(tmp_path / "run.csv")
    with pytest.raises(InputError, match=r"row 3001 \(line 3002\): --gaps split cuts this "
                                         r"recording at 2 time gaps into 3 pieces, and this "
                                         r"command reads it as one recording"):
        read_recording(path, options=ReadOptions(gaps="split"))


def test_a_piece_is_checked_as_a_recording_naming_the_files_row(tmp_path):
    time = np.r_[np.arange(10), 20 + np.arange(10)] * 0.025
    time[15] += 0.001  # jitter inside the second piece: no gap, still not uniform
    path = tmp_path / "jitter.csv"
    pd.DataFrame({"time": time, "position": np.ones(20), "sensor": np.arange(20.0)}).to_csv(
        path, index=False, float_format="%.17g")
    with pytest.raises(InputError, match=r"row 16 \(line 17\): non-uniform sampling"):
        read_pieces(path)
    time = np.r_[np.arange(10), 20, 30 + np.arange(10)] * 0.025  # a lone sample between gaps
    pd.DataFrame({"time": time, "position": np.ones(21), "sensor": np.arange(21.0)}).to_csv(
        path, index=False, float_format="%.17g")
    with pytest.raises(InputError, match=r"column 'time', row 11 \(line 12\): a single sample "
                                         r"between two time gaps"):
        read_pieces(path)


def test_missing_rows_and_resampling_per_piece(tmp_path, capsys):
    rec = simulate_experiment("noise", seed=1)
    path = _gapped(tmp_path / "run.csv", rec)
    frame = pd.read_csv(path, dtype=str)
    frame.loc[[0, 7999], "sensor"] = ""  # at the ends: dropped without a gap
    frame.to_csv(path, index=False)
    pieces = read_pieces(path, options=ReadOptions(missing="drop", resample_hz=20.0))
    said = capsys.readouterr().err
    assert "rows 2-3000, 3001-6000, 6001-7999" in said  # the file's rows, the dropped left out
    assert [p.fs for p in pieces] == pytest.approx([20.0] * 3, rel=1e-9)


def test_time_gaps_threshold_is_three_median_steps():
    time = np.r_[0.0, 1.0, 2.0, 5.0, 6.0, 9.01, 10.01]
    assert_array_equal(time_gaps(time), [4])  # a step of 3 is no gap, 3.01 is


def test_settings_key_and_hk_fit_fits_the_pieces_jointly(tmp_path, capsys):
    path = _gapped(tmp_path / "run.csv")
    settings = path.with_suffix(".toml")
    settings.write_text('gaps = "split"\n')
    assert read_recording_config(settings) == {"gaps": "split"}
    capsys.readouterr()
    comp = hk.fit(path, "mpl", size=1, band=False, diagnose=False)
    err = capsys.readouterr().err
    assert "2 time gaps, read as 3 pieces fitted jointly" in err
    assert comp.fit_info["training_sources"] == [f"{path} (piece {k} of 3)" for k in (1, 2, 3)]
    assert comp.fit_info["joint_fit"].startswith("joint polish over 3 recordings")
    with pytest.raises(ValueError, match="gaps must be one of error, split, got 'join'"):
        ReadOptions(gaps="join")


def test_the_cli_reads_pieces_for_a_joint_fit(tmp_path, capsys):
    path = _gapped(tmp_path / "run.csv")
    plain = tmp_path / "plain.csv"
    simulate_experiment("noise", seed=2).to_frame().to_csv(plain, index=False)
    parser = Parser(prog="hystkit fit")
    add_read_options(parser)
    args = parser.parse_args(["--gaps", "split"])
    reading, recordings = Reader(given_read_options(args)).training_files([path, plain])
    assert [r.gaps for r in reading] == ["split", "split"]
    assert [r.n_samples for r in recordings] == [3000, 3000, 2000, 8000]
    joint = fit_compensator(recordings, 1, diagnose=False)
    assert joint.fit_info["joint_fit"].startswith("joint polish over 4 recordings")
    with pytest.raises(InputError, match="a time gap: split the recording there"):
        Reader(given_read_options(parser.parse_args([]))).training_files([path])


def test_hystkit_fit_gaps_split_fits_the_pieces_jointly(tmp_path, capsys):
    path = _gapped(tmp_path / "run.csv")
    model = tmp_path / "m.json"
    assert main(["fit", str(path), "--model", "mpl", "--gaps", "split", "--no-band", "--out",
                 str(model)]) == 0
    info = json.loads(model.read_text())["fit"]
    assert info["joint_fit"].startswith("joint polish over 3 recordings")
    assert info["training_samples"] == 8000
    assert main(["fit", str(path), "--model", "mpl", "--out", str(tmp_path / "refused.json")]) == 2
    assert "--gaps split" in capsys.readouterr().err
