"""``hystkit warm`` compiles ahead what ``fit`` needs, into numba's cache (issue 29); a run
that has to compile says so once on stderr. Run as the program in fresh interpreters sharing
an empty numba cache folder (about 20 s of compilation: the mPL family only)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from hystkit.cli._main import COMPILING_NOTICE, main
from hystkit.io import write_recording
from hystkit.sensors import simulate_experiment


def _hystkit(cache: Path, *argv: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-m", "hystkit", *argv], capture_output=True,
                          text=True, env=env, cwd=cwd, timeout=900, check=False)
    assert done.returncode == 0, done.stderr
    return done


def test_warm_compiles_what_fit_needs_and_a_cold_run_says_it_compiles(tmp_path):
    cache = tmp_path / "numba-cache"
    write_recording(simulate_experiment("noise", 1), tmp_path / "fit.csv")

    warm = _hystkit(cache, "warm", "--models", "mpl", "--no-control", cwd=tmp_path)
    lines = warm.stdout.splitlines()
    assert lines[0].startswith("hystkit warm: compiling the numba kernels of fit, evaluate, "
                               "stream and compare")
    assert str(cache) in lines[0]
    assert [line.split(":")[0].strip() for line in lines[1:3]] == ["[1/2] recordings",
                                                                   "[2/2] mpl"]
    assert lines[-1].startswith("done in ")
    assert COMPILING_NOTICE not in warm.stderr  # its progress lines say it
    assert list(cache.rglob("kernels.normal_equations-*.nbi"))  # the mPL's

    fit = _hystkit(cache, "fit", "fit.csv", "--model", "mpl", "--out", "mpl.json", cwd=tmp_path)
    assert COMPILING_NOTICE not in fit.stderr  # everything loaded from the cache
    stream = _hystkit(cache, "stream", "mpl.json", "--in", "fit.csv", cwd=tmp_path)
    assert COMPILING_NOTICE not in stream.stderr  # its per-sample kernel too

    cold = _hystkit(cache, "fit", "fit.csv", "--model", "pi", "--out", "pi.json",
                    cwd=tmp_path)
    assert cold.stderr.count(COMPILING_NOTICE) == 1  # PI's kernels were not warmed


def test_an_unknown_family_is_one_error_line(capsys):
    assert main(["warm", "--models", "mpl,nope"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("hystkit: error: --models mpl,nope: choose among ")
    assert len(err.splitlines()) == 1


def test_warm_help_names_its_options(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["warm", "--help"])
    assert stop.value.code == 0
    assert "--models" in capsys.readouterr().out
