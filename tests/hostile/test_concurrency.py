"""Concurrent writers of one output: exactly one wins, nothing interleaved or partial.

Two ``hystkit compensate ... --out same.csv`` processes start together. Without ``--force``
exactly one succeeds; the other exits 2 with one line saying the file exists (whether it
noticed before or after its work), and the file is the winner's complete content, byte for
byte what a single run writes. With ``--force`` both succeed and the file is still one
complete run's content (atomic replace), never a mix.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hystkit.cli import main

from .conftest import Run, entries

N_ROWS = 50_000  # a few MB of CSV: the two writers overlap in their work


@pytest.fixture(scope="module")
def inputs(good: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The model and a long recording (the validation sensor signal repeated), and the
    output of a single, undisturbed run to compare with."""
    folder = tmp_path_factory.mktemp("race-inputs")
    sensor = pd.read_csv(good["val"])["sensor"].to_numpy()
    data = folder / "long.csv"
    pd.DataFrame({"time": np.arange(N_ROWS) / 40.0,
                  "sensor": np.resize(sensor, N_ROWS)}).to_csv(data, index=False)
    single = folder / "single.csv"  # in-process: the same code writes the same bytes
    assert main(["compensate", str(good["model"]), str(data), "--out", str(single)]) == 0
    return {"model": good["model"], "data": data, "single": single}


def _together(*argv: object, cwd: Path, n: int = 2) -> list[Run]:
    """Start `n` identical commands at once; wait for all."""
    procs = [subprocess.Popen([sys.executable, "-m", "hystkit", *map(str, argv)], cwd=cwd,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              env={**os.environ, "MPLBACKEND": "Agg"})
             for _ in range(n)]
    runs = []
    for proc in procs:
        out, err = proc.communicate(timeout=120)
        runs.append(Run(proc.returncode, out, err))
    return runs


def test_two_writers_without_force_exactly_one_wins(inputs: dict[str, Path],
                                                    tmp_path: Path) -> None:
    runs = _together("compensate", inputs["model"], inputs["data"], "--out", "same.csv",
                     cwd=tmp_path)
    codes = sorted(r.code for r in runs)
    assert codes == [0, 2], [r.err for r in runs]
    loser = next(r for r in runs if r.code == 2)
    loser.error_line("same.csv", "already exists", "--force")
    assert (tmp_path / "same.csv").read_bytes() == inputs["single"].read_bytes()
    assert entries(tmp_path) == ["same.csv"]  # no temporaries left by either


def test_two_writers_with_force_leave_one_complete_file(inputs: dict[str, Path],
                                                        tmp_path: Path) -> None:
    (tmp_path / "same.csv").write_text("old\n")
    runs = _together("compensate", inputs["model"], inputs["data"], "--out", "same.csv",
                     "--force", cwd=tmp_path)
    for run in runs:
        run.clean()
        assert run.code == 0, run.err
    assert (tmp_path / "same.csv").read_bytes() == inputs["single"].read_bytes()
    assert entries(tmp_path) == ["same.csv"]
