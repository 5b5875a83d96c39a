"""Shared tools of the hostile-input corpus (issue 10).

Every case runs a ``hystkit`` command the way a hostile user would and checks the promise:
the expected exit code, at most one ``hystkit: error:`` line naming what was wrong, no
traceback, and the output folder exactly as it was (nothing written, nothing overwritten,
nothing partial). Cases that can crash or hang the interpreter (segfaults, signals, races) run
in a subprocess; the rest in-process through ``main(argv)``, which is much faster.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import pytest

from hystkit.cli import main

matplotlib.use("Agg")


@dataclass
class Run:
    """What one command did."""

    code: int
    out: str
    err: str

    def error_line(self, *fragments: object) -> str:
        """Assert stderr is exactly one ``hystkit: error:`` line holding every fragment."""
        assert "Traceback" not in self.err and "Traceback" not in self.out, self.err
        lines = [line for line in self.err.splitlines() if line.strip()]
        errors = [line for line in lines if line.startswith("hystkit: error: ")]
        assert len(errors) == 1, f"expected one error line, got:\n{self.err}"
        for fragment in fragments:
            assert str(fragment).lower() in errors[0].lower(), \
                f"{fragment!r} not in {errors[0]!r}"
        return errors[0]

    def clean(self) -> None:
        """No traceback, no crash-by-signal."""
        assert "Traceback" not in self.err and "Traceback" not in self.out, self.err
        assert self.code >= 0, f"killed by signal {-self.code}"


@pytest.fixture
def cli(capsys: pytest.CaptureFixture[str]) -> Callable[..., Run]:
    """Run ``hystkit ARGS`` in-process; returns a `Run`."""

    def run(*argv: object) -> Run:
        capsys.readouterr()
        code = main([str(a) for a in argv])
        out, err = capsys.readouterr()
        return Run(code, out, err)

    return run


def run_subprocess(*argv: object, cwd: Path | None = None, timeout: float = 300,
                   env: dict[str, str] | None = None) -> Run:
    """Run ``python -m hystkit ARGS`` in a child process (crashes and signals stay there)."""
    proc = subprocess.run([sys.executable, "-m", "hystkit", *map(str, argv)], check=False,
                          cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, "MPLBACKEND": "Agg", **(env or {})})
    return Run(proc.returncode, proc.stdout, proc.stderr)


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file below `folder` with its bytes (compare before and after a command)."""
    return {str(p.relative_to(folder)): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def entries(folder: Path) -> list[str]:
    """Every path below `folder` (files and folders), to see stray temporaries."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.fixture(scope="session")
def good(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Valid inputs every case starts from (never modify them; copy first): ``fit``/``val``
    CSV recordings (virtual sensor, sine, seeds 1 and 2), their Parquet and ``.mat`` twins,
    and ``model``, a 1-cell mPL compensator fitted on ``fit``."""
    import numpy as np
    import pandas as pd
    from scipy.io import savemat

    folder = tmp_path_factory.mktemp("good")
    paths = {"fit": folder / "fit.csv", "val": folder / "val.csv", "model": folder / "model.json"}
    for seed, key in ((1, "fit"), (2, "val")):
        assert main(["simulate-sensor", "--excitation", "sine", "--seed", str(seed),
                     "--out", str(paths[key])]) == 0
    assert main(["fit", str(paths["fit"]), "--cells", "1", "--out", str(paths["model"])]) == 0
    table = pd.read_csv(paths["val"])
    paths["val_parquet"] = folder / "val.parquet"
    table.to_parquet(paths["val_parquet"], index=False)
    paths["val_mat"] = folder / "val.mat"
    savemat(paths["val_mat"], {name: np.asarray(table[name]) for name in table.columns})
    for path in paths.values():
        path.chmod(0o444)  # a case that writes to its input fails loudly
    return paths


def assert_model_file_refused(cli, good: dict[str, Path], path: Path, folder: Path,
                              *fragments: object) -> None:
    """`evaluate` and `compensate` with the model file `path` both exit 2 with one error line
    naming the file and every fragment, and write nothing into `folder`."""
    before = snapshot(folder)
    for argv in (["evaluate", path, good["val"], "--json", folder / "scores.json"],
                 ["compensate", path, good["val"], "--out", folder / "out.csv"]):
        run = cli(*argv)
        assert run.code == 2, (argv[0], run.err)
        run.error_line(path.name, *fragments)
    assert snapshot(folder) == before  # nothing written, the model untouched
