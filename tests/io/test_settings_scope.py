"""A settings file applies to the file it is for, never silently to another format of the same
stem (issue 27.1): ``my.toml`` written for ``my.csv`` in ms is not applied to ``my.mat`` in s."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import scipy.io

import hystkit as hk
from hystkit.cli import main
from hystkit.errors import InputError
from hystkit.io import Recording, options_for, read_recording, settings_for, write_recording

SETTINGS = 'time_unit = "ms"\nsep = ";"\n\n[columns]\ntime = "t_ms"\nsensor = "R"\n'


def _truth(n: int = 400) -> Recording:
    t = np.arange(n) * 0.02
    return Recording(time=t, position=np.sin(2 * np.pi * 0.5 * t),
                     sensor=100 + np.sin(2 * np.pi * 0.5 * t - 0.3))


@pytest.fixture
def pair(tmp_path) -> dict[str, Path]:
    """The same run as a lab CSV (ms, ';', own names) and as a MATLAB file (s, hystkit's)."""
    rec = _truth()
    csv = tmp_path / "run.csv"
    rows = ["t_ms;position;R"] + [";".join(repr(float(v)) for v in row) for row in
                                  zip(rec.time * 1e3, rec.position, rec.sensor)]
    csv.write_text("\n".join(rows) + "\n", encoding="utf-8")
    mat = tmp_path / "run.mat"
    scipy.io.savemat(mat, {"time": rec.time, "position": rec.position, "sensor": rec.sensor})
    return {"csv": csv, "mat": mat, "toml": tmp_path / "run.toml", "rec": rec}


def _assert_is(back: Recording, rec: Recording) -> None:
    np.testing.assert_allclose(back.time, rec.time, rtol=1e-15, atol=1e-15)  # ms -> s: 1 ulp
    np.testing.assert_array_equal(back.sensor, rec.sensor)


def test_settings_beside_two_formats_must_say_which_file_they_are_for(pair):
    pair["toml"].write_text(SETTINGS, encoding="utf-8")
    for data in (pair["csv"], pair["mat"]):
        with pytest.raises(InputError) as err:
            options_for(data)
        assert str(err.value) == (
            f"{pair['toml']}: settings beside {data.name} and "
            f"{(pair['mat'] if data == pair['csv'] else pair['csv']).name}, which may differ "
            f"(a time unit, a separator): say which file they are for with file = "
            f"\"{data.name}\" in it (the other is then read with options given on the "
            "command line)")


@pytest.mark.parametrize("target", ["run.csv", "*.csv", ".csv"])
def test_settings_for_the_csv_are_not_applied_to_the_mat(pair, target):
    pair["toml"].write_text(f'file = "{target}"\n' + SETTINGS, encoding="utf-8")
    options, settings = options_for(pair["csv"])
    assert settings == pair["toml"]
    _assert_is(read_recording(pair["csv"], options=options), pair["rec"])
    options, settings = options_for(pair["mat"])
    assert settings is None
    assert settings_for(pair["mat"]) == (None, f"{pair['toml']} is for {target}")
    # in s as the .mat holds it: not 'sampled every 2e-05 s' from the CSV's time_unit = "ms"
    _assert_is(read_recording(pair["mat"], options=options), pair["rec"])


def test_settings_for_one_file_alone_apply_as_before(pair):
    pair["mat"].unlink()
    pair["toml"].write_text(SETTINGS, encoding="utf-8")
    assert settings_for(pair["csv"]) == (pair["toml"], "")
    _assert_is(read_recording(pair["csv"], options=options_for(pair["csv"])[0]), pair["rec"])


@pytest.mark.parametrize("target", ["other.csv", "run.txt", "*.txt", "sub/run.csv"])
def test_a_file_they_cannot_be_for_is_refused(pair, target):
    pair["toml"].write_text(f'file = "{target}"\n' + SETTINGS, encoding="utf-8")
    with pytest.raises(InputError, match=re.escape(
            f"run.toml: key 'file' = '{target}': settings found by their name are for "
            "run.csv, run.parquet, run.mat (or one extension")):
        options_for(pair["csv"])


def test_the_python_api_says_which_settings_it_applied(pair, capsys):
    pair["toml"].write_text('file = "run.csv"\n' + SETTINGS, encoding="utf-8")
    capsys.readouterr()
    _assert_is(hk.read(pair["csv"]), pair["rec"])
    assert capsys.readouterr().err.splitlines() == [
        f"hystkit: reading {pair['csv']} with the settings in {pair['toml']}"]
    _assert_is(hk.read(pair["mat"]), pair["rec"])
    assert capsys.readouterr().err.splitlines() == [
        f"hystkit: reading {pair['mat']} without its settings: {pair['toml']} is for run.csv"]
    pair["toml"].unlink()
    _assert_is(hk.read(pair["mat"]), pair["rec"])
    assert capsys.readouterr().err == ""


def test_the_command_line_says_it_and_refuses_the_clash(pair, tmp_path, capsys):
    pair["toml"].write_text(SETTINGS, encoding="utf-8")
    capsys.readouterr()
    assert main(["fit", str(pair["mat"]), "--cells", "1", "--out", str(tmp_path / "m.json")]) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [(f"hystkit: error: {pair['toml']}: settings beside run.mat and "
                                "run.csv, which may differ (a time unit, a separator): say "
                                "which file they are for with file = \"run.mat\" in it (the "
                                "other is then read with options given on the command line)")]
    pair["toml"].write_text('file = "run.csv"\n' + SETTINGS, encoding="utf-8")
    assert main(["fit", str(pair["mat"]), "--cells", "1", "--out", str(tmp_path / "m.json")]) == 0
    out = capsys.readouterr().out
    assert f"reading {pair['mat']} without its settings: {pair['toml']} is for run.csv" in out
    assert main(["fit", str(pair["csv"]), "--cells", "1", "--out", str(tmp_path / "c.json")]) == 0
    out = capsys.readouterr().out
    assert f"reading {pair['csv']} with the settings in {pair['toml']}" in out


def test_the_units_file_hystkit_writes_names_its_recording(tmp_path):
    rec = Recording(time=[0.0, 0.1, 0.2], sensor=[1.0, 2.0, 3.0], position=[0.0, 1.0, 2.0],
                    units={"position": "mm", "sensor": "Ohm"})
    out = write_recording(rec, tmp_path / "c.csv", units_sidecar=True)
    assert 'file = "c.csv"' in (tmp_path / "c.toml").read_text(encoding="utf-8")
    write_recording(rec, tmp_path / "c.mat")  # the same run in MATLAB beside it
    assert settings_for(out) == (tmp_path / "c.toml", "")
    assert dict(read_recording(out, options=options_for(out)[0]).units) == {
        "position": "mm", "sensor": "Ohm"}
    assert settings_for(tmp_path / "c.mat") == (None, f"{tmp_path / 'c.toml'} is for c.csv")
