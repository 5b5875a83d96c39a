"""README.md's walk-through "Your own files" runs as written (issue 11): a user's CSV with
other column names, time in ms and a units line, fitted, scored, compensated, saved to .mat.

The bash block is run by bash in a temporary folder with this interpreter's ``hystkit`` and
``python`` first on PATH; its answers are then checked against each other and the input.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.io import loadmat

README = Path(__file__).resolve().parents[2] / "README.md"
_HEADING = re.compile(r"^(#+) +(.*)$", re.MULTILINE)
_FENCE = re.compile(r"^```.*?^```", re.MULTILINE | re.DOTALL)
_BASH = re.compile(r"^```bash\n(.*?)^```", re.MULTILINE | re.DOTALL)


def walkthrough() -> str | None:
    """The bash block of the section whose title starts with "Your own files" that saves to
    .mat, or None when the README has none yet."""
    text = README.read_text(encoding="utf-8")
    fences = [m.span() for m in _FENCE.finditer(text)]  # a "# comment" in code is no heading
    headings = [h for h in _HEADING.finditer(text)
                if not any(a <= h.start() < b for a, b in fences)]
    for i, heading in enumerate(headings):
        if not heading.group(2).startswith("Your own files"):
            continue
        level = len(heading.group(1))
        end = next((h.start() for h in headings[i + 1:] if len(h.group(1)) <= level),
                   len(text))
        for block in _BASH.finditer(text, heading.end(), end):
            if "compensate" in block.group(1) and ".mat" in block.group(1):
                return block.group(1)
    return None


def test_readme_walkthrough_runs(tmp_path):
    code = walkthrough()
    if code is None:
        pytest.skip("README.md has no section 'Your own files' with the .mat walk-through "
                    "yet (the lead merges /work/notes/readme_data.md)")
    bin_dir = str(Path(sys.executable).parent)  # this venv's hystkit and python
    env = {**os.environ, "PATH": bin_dir + os.pathsep + os.environ.get("PATH", "")}
    proc = subprocess.run(["bash", "-euo", "pipefail", "-c", code], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=900, check=False)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "hystkit: error" not in proc.stderr

    # the user's file: ms and their names; the answers: the same names and ms (issue 27.4)
    own = pd.read_csv(tmp_path / "my.csv", skiprows=[1])
    c = loadmat(tmp_path / "compensated.mat", simplify_cells=True)
    assert_allclose(c["t_ms"], own["t_ms"].to_numpy(), rtol=1e-15, atol=0)
    assert_array_equal(c["displacement_mm"], own["displacement_mm"].to_numpy())
    assert_array_equal(c["resistance_ohm"], own["resistance_ohm"].to_numpy())
    band = [f"displacement_mm_{side}" for side in ("lower", "upper") if
            f"displacement_mm_{side}" in c]  # the band's columns, when the model has one
    assert c["units"] == {"t_ms": "ms", "displacement_mm": "mm", "resistance_ohm": "Ohm",
                          "displacement_mm_estimate": "mm", **dict.fromkeys(band, "mm")}
    # evaluate and compensate ran without options: as the model's training data were read
    assert proc.stdout.count("reading my.csv as the model's training data were read: "
                             "columns t_ms,displacement_mm,resistance_ohm, time in ms, a "
                             "units line") == 2
    # the same answer from the settings file, in CSV
    written = pd.read_csv(tmp_path / "compensated.csv")
    assert_array_equal(written["displacement_mm_estimate"].to_numpy(),
                       c["displacement_mm_estimate"])

    # scores.mat's R² is that of compensated.mat's estimate (1 - SS_res / SS_tot)
    x, estimate = c["displacement_mm"], c["displacement_mm_estimate"]
    r2 = 1 - np.sum((x - estimate) ** 2) / np.sum((x - x.mean()) ** 2)
    s = loadmat(tmp_path / "scores.mat", simplify_cells=True)
    assert s["r2"] == pytest.approx(r2, rel=1e-9)
    assert s["r2"] > 0.9  # the mPL compensator on the virtual sensor's sine
    assert s["units"] == {"position": "mm", "sensor": "Ohm"}

    # the model as a MATLAB struct: every field of the JSON model file
    m = loadmat(tmp_path / "model.mat", simplify_cells=True)
    # the model the guided fit says it chose (mpl on a quiet machine; under a heavy load its
    # time budget can skip the larger candidates and pi wins: seen once at load 7)
    chosen = re.search(r"^chose (\S+) \(size", proc.stdout, re.MULTILINE)
    assert chosen is not None, proc.stdout[-2000:]
    assert m["schema"] == "hystkit.compensator" and m["model"] == chosen.group(1)
    assert m["fit"]["units"] == {"position": "mm", "sensor": "Ohm"}
