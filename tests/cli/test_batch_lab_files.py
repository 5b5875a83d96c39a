"""``hystkit batch`` reads each recording as ``fit`` does (issue 27.2): its settings file
beside it, then the command line's reading options; a fleet laid out like single-sensor work
is fitted, not failed sensor by sensor."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from hystkit.batch import SensorJob
from hystkit.batch._run import fit_sensor
from hystkit.cli._main import main
from hystkit.io import Recording, write_recording
from hystkit.sensors import simulate_experiment

SETTINGS = ('time_unit = "ms"\n\n[columns]\ntime = "t_ms"\nposition = "x_mm"\n'
            'sensor = "R_ohm"\n')
SCORES = ["status", "r2_deployable", "e_rms_pct_deployable", "r2_oracle"]


def _run(k: int, role: str) -> Recording:
    rec = simulate_experiment("sine", (40 if role == "fit" else 50) + k)
    return Recording(time=rec.time[:2400], sensor=rec.sensor[:2400],
                     position=rec.position[:2400])


def _lab_csv(path: Path, rec: Recording) -> Path:
    """As Excel in Europe saves it: a comment line, ';', decimal commas, ms, own names."""
    rows = ["# bench 2", "t_ms;x_mm;R_ohm"]
    rows += [f"{float(t) * 1e3!r};{float(p)!r};{float(s)!r}".replace(".", ",")
             for t, p, s in zip(rec.time, rec.position, rec.sensor)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two sensors in hystkit's own files, the same two as lab files with settings beside
    each, and the same two as lab files without (options on the command line)."""
    folder = tmp_path_factory.mktemp("labfleet")
    manifests = {}
    for kind in ("std", "toml", "options"):
        lines = ["sensor,fit,validate,model,size"]
        for k in range(2):
            for role in ("fit", "val"):
                path = folder / f"{kind}{k}_{role}.csv"
                if kind == "std":
                    write_recording(_run(k, role), path)
                else:
                    _lab_csv(path, _run(k, role))
                if kind == "toml":
                    path.with_suffix(".toml").write_text(SETTINGS, encoding="utf-8")
            lines.append(f"s{k},{kind}{k}_fit.csv,{kind}{k}_val.csv,mpl,1")
        manifests[kind] = folder / f"{kind}.csv"
        manifests[kind].write_text("\n".join(lines) + "\n", encoding="utf-8")
    return manifests


def _table(out: Path) -> pd.DataFrame:
    return pd.read_parquet(out / "results.parquet")


def test_settings_files_and_options_give_the_table_of_hystkits_own_files(fleet, tmp_path,
                                                                         capsys):
    own = ["--columns", "time=t_ms,position=x_mm,sensor=R_ohm", "--time-unit", "ms"]
    runs = {"std": [], "toml": [], "options": own}
    for kind, extra in runs.items():
        capsys.readouterr()
        assert main(["batch", str(fleet[kind]), "--out", str(tmp_path / kind), "--workers",
                     "1", *extra]) == 0, capsys.readouterr()
        out = capsys.readouterr().out
        said = [line for line in out.splitlines() if line.startswith("reading ")]
        lab = fleet[kind].parent / f"{kind}0_fit.csv"
        if kind == "toml":
            assert f"reading {lab} with the settings in {lab.with_suffix('.toml')}" in said
        if kind != "std":
            assert f"reading {lab}: semicolon-separated, decimal comma, 1 comment line " \
                   "before the header skipped" in said
        else:
            assert said == []
    std = _table(tmp_path / "std")[SCORES]
    assert list(std["status"]) == ["ok", "ok"]
    for kind in ("toml", "options"):
        # ms through a decimal comma: the same samples to an ulp of time, the same scores
        pd.testing.assert_frame_equal(_table(tmp_path / kind)[SCORES], std, rtol=1e-9)


def test_an_edited_settings_file_refits_on_rerun(fleet, tmp_path, capsys):
    out = tmp_path / "rerun"
    assert main(["batch", str(fleet["toml"]), "--out", str(out), "--workers", "1"]) == 0
    assert main(["batch", str(fleet["toml"]), "--out", str(out), "--workers", "1"]) == 0
    assert "2 sensors: 2 finished before, 0 to fit" in capsys.readouterr().out
    settings = fleet["toml"].parent / "toml1_val.toml"
    original = settings.read_text(encoding="utf-8")
    try:
        settings.write_text(original + '\n[units]\nposition = "mm"\n', encoding="utf-8")
        assert main(["batch", str(fleet["toml"]), "--out", str(out), "--workers", "1"]) == 0
        assert "2 sensors: 1 finished before, 1 to fit" in capsys.readouterr().out
    finally:
        settings.write_text(original, encoding="utf-8")


def test_a_refused_settings_file_stops_the_batch_before_any_fit(fleet, tmp_path, capsys):
    folder = tmp_path / "clash"
    folder.mkdir()
    for role in ("fit", "val"):
        _lab_csv(folder / f"a_{role}.csv", _run(0, role))
        (folder / f"a_{role}.toml").write_text(SETTINGS, encoding="utf-8")
    write_recording(_run(0, "fit"), folder / "a_fit.mat")  # the same run, in s, beside it
    manifest = folder / "m.csv"
    manifest.write_text("sensor,fit,validate\na,a_fit.csv,a_val.csv\n", encoding="utf-8")
    capsys.readouterr()
    assert main(["batch", str(manifest), "--out", str(folder / "out")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [(f"hystkit: error: {folder / 'a_fit.toml'}: settings beside a_fit.csv and "
                    "a_fit.mat, which may differ (a time unit, a separator): say which file "
                    "they are for with file = \"a_fit.csv\" in it (the other is then read "
                    "with options given on the command line)")]
    assert not (folder / "out").exists()


def test_the_library_reads_each_file_with_its_settings_by_default(fleet):
    folder = fleet["toml"].parent
    job = SensorJob("s0", (folder / "toml0_fit.csv",), (folder / "toml0_val.csv",), size=1)
    result = fit_sensor(job)
    assert result["row"]["status"] == "ok", result["row"]["error"]
