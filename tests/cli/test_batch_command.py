"""``hystkit batch``: a fleet on two local Dask workers gives the serial table; reruns resume;
failures are listed with exit 3; bad input is one line, exit 2."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from hystkit.cli._main import main
from hystkit.io import Recording, write_recording
from hystkit.sensors import simulate_experiment

TIMES = ["fit_seconds", "seconds"]


@pytest.fixture(scope="module")
def manifest(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fleet")
    lines = ["sensor,fit,validate,model,size"]
    for k in range(3):
        for role, seed in (("fit", 40 + k), ("val", 50 + k)):
            rec = simulate_experiment("sine", seed)
            write_recording(Recording(time=rec.time[:2400], sensor=rec.sensor[:2400],
                                      position=rec.position[:2400], source=rec.source),
                            folder / f"t{k}_{role}.csv")
        lines.append(f"t{k},t{k}_fit.csv,t{k}_val.csv,mpl,1")
    (folder / "fleet.csv").write_text("\n".join(lines) + "\n")
    return folder / "fleet.csv"


def _table(out: Path) -> pd.DataFrame:
    return pd.read_parquet(out / "results.parquet")


def test_batch_on_two_workers_writes_the_serial_table(manifest, tmp_path, capsys):
    assert main(["batch", str(manifest), "--out", str(tmp_path / "serial"),
                 "--workers", "1"]) == 0
    assert main(["batch", str(manifest), "--out", str(tmp_path / "dask"), "--workers", "2"]) == 0
    out = capsys.readouterr().out
    assert "3 to fit on 2 Dask workers (local" in out
    assert sum(line.startswith("[") and ": ok, R²" in line for line in out.splitlines()) == 6
    serial, dask = _table(tmp_path / "serial"), _table(tmp_path / "dask")
    assert list(dask["sensor"]) == ["t0", "t1", "t2"]  # the manifest's order
    pd.testing.assert_frame_equal(dask.drop(columns=TIMES), serial.drop(columns=TIMES))
    for sensor in ("t0", "t1", "t2"):  # the same model files, but for the fits' own times
        a = (tmp_path / "serial" / "models" / f"{sensor}.json").read_text().splitlines()
        b = (tmp_path / "dask" / "models" / f"{sensor}.json").read_text().splitlines()
        assert [x for x, y in zip(a, b) if x != y and "fit_seconds" not in x] == []

    # a rerun finds everything done and rewrites the same table
    assert main(["batch", str(manifest), "--out", str(tmp_path / "dask"), "--workers", "1"]) == 0
    assert "3 sensors: 3 finished before, 0 to fit" in capsys.readouterr().out
    pd.testing.assert_frame_equal(_table(tmp_path / "dask"), dask)


def test_a_failed_sensor_gives_exit_3_after_the_others(manifest, tmp_path, capsys):
    text = manifest.read_text().replace("t1_fit.csv", "missing.csv")
    bad = manifest.with_name("with-missing.csv")
    bad.write_text(text)
    assert main(["batch", str(bad), "--out", str(tmp_path / "out"), "--workers", "1"]) == 3
    captured = capsys.readouterr()
    assert "t1: FAILED: " in captured.out and "missing.csv" in captured.out
    assert captured.err.strip() == "hystkit: 1 sensor(s) failed: t1 (reasons above)"
    table = _table(tmp_path / "out")
    assert list(table["status"]) == ["ok", "failed", "ok"]


@pytest.mark.parametrize(("args", "message"), [
    (["nowhere.csv"], "nowhere.csv: no such manifest or folder"),
    (["{manifest}", "--size", "0"], "--size"),
    (["{manifest}", "--model", "nope"], "--model"),
])
def test_bad_input_is_one_line(manifest, tmp_path, capsys, args, message):
    argv = ["batch", *(a.format(manifest=manifest) for a in args), "--out", str(tmp_path / "o")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("hystkit: error:") and message in err
    assert not (tmp_path / "o").exists()


def test_a_batch_killed_after_its_first_sensor_resumes_to_the_same_table(manifest, tmp_path):
    """Ctrl-C on the running command (two Dask workers): one line, exit 130; the rerun fits
    only what was not finished and writes the table of an uninterrupted run."""
    import os
    import signal
    import subprocess
    import sys

    out = tmp_path / "killed"
    # SIGINT handled as in a terminal even when the test session runs as a background job
    # (which starts with SIGINT ignored, inherited across exec)
    with_ctrl_c = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler)"
                   "; from hystkit.cli import main; sys.exit(main())")
    proc = subprocess.Popen([sys.executable, "-c", with_ctrl_c, "batch", str(manifest), "--out",
                             str(out), "--workers", "2"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env={**os.environ, "PYTHONUNBUFFERED": "1"})
    for line in proc.stdout:  # the first finished sensor
        if line.startswith("[1/3]"):
            break
    os.killpg(proc.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole process group
    rest, err = proc.communicate(timeout=60)
    assert (proc.returncode, err.splitlines()) == (130, ["hystkit: interrupted"]) or \
        (proc.returncode == 0 and "wrote" in rest)  # finished before the signal arrived
    finished = len(list((out / "sensors").iterdir()))
    assert finished >= 1
    assert main(["batch", str(manifest), "--out", str(out), "--workers", "1"]) == 0
    assert main(["batch", str(manifest), "--out", str(tmp_path / "whole"), "--workers", "1"]) == 0
    pd.testing.assert_frame_equal(_table(out).drop(columns=TIMES),
                                  _table(tmp_path / "whole").drop(columns=TIMES))
