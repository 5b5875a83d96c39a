"""Helpers of the export tests: the families exported, compensators built from each family's
documented parameter domain on the virtual sensor's conventions, compiling and running C."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from hystkit.compensation import (
    Compensator,
    LinearBaseline,
    fit_compensator,
    prepare_training_data,
)
from hystkit.errors import HystkitError
from hystkit.models import get_family

# (label, family, size): the families the issue asks for, mpl with 1 and 3 cells.
CASES = [("mpl1", "mpl", 1), ("mpl3", "mpl", 3), ("mpl-poly", "mpl-poly", 1), ("pi", "pi", 6),
         ("preisach", "preisach", 12), ("gpreisach", "gpreisach", 10), ("ladder", "ladder", 3),
         ("boucwen", "boucwen", 1), ("bobbio", "bobbio", 6),
         ("chua", "chua", 2), ("pl", "pl", 2)]
# Families whose export is checked by a test file of their own instead (C and Octave against
# Python, every mode and centring), not through CASES.
OWN_EXPORT_TESTS = {"mpl-g": "tests/models/test_mpl_g_export.py"}
# (label, mode) pairs: inverse only where the family has one.
MODE_CASES = [(label, mode) for label, model, _ in CASES for mode in ("direct", "inverse")
              if mode == "direct" or get_family(model).invert is not None]
CENTRINGS = ("fit", "tare", "track")
STRICT_FLAGS = ["-O2", "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]


def build_compensator(train, val, model: str, size: int, mode: str, center: str) -> Compensator:
    """A compensator fitted on ``train`` (the realistic case); if that one diverges on the
    validation recording (some inverse fits do), the first parameter set (seed 0, 1, ...) of the
    family's documented domain whose run stays finite, on the same conventions."""
    from dataclasses import replace

    conventions, s, _ = prepare_training_data([train], center)
    try:
        comp = fit_compensator(train, size, model=model, mode=mode, center=center,
                               diagnose=False)
        comp.estimate(val)
        return comp
    except HystkitError:
        pass
    family = get_family(model)
    structure = family.make_structure(train.dt, size)
    for seed in range(40):
        params = family.random_params(structure, np.random.default_rng(seed))
        try:
            comp = Compensator(
                structure=structure, params=params, mode=mode, center=center,
                baseline=LinearBaseline(1.0, 0.0), model=model,
                training_range=(float(np.min(s[0])), float(np.max(s[0]))),
                position_range=(float(np.min(train.position)), float(np.max(train.position))),
                **conventions)
            comp.estimate(val)
        except (HystkitError, ValueError):
            continue
        return replace(comp, fit_info={"drawn": f"random_params seed {seed}"})
    raise AssertionError(f"no usable {model} {mode} compensator (fit or 40 draws)")


def need(tool: str) -> str:
    path = shutil.which(tool)
    if path is None:
        pytest.skip(f"{tool} is not installed (CI installs it)")
    return path


def compile_c(folder: Path, output: str = "estimate") -> Path:
    """Build the export in ``folder`` with the strict flags; fail the test on any warning."""
    cc = need("cc")
    sources = sorted(str(p.name) for p in folder.glob("*.c"))
    run = subprocess.run([cc, *STRICT_FLAGS, *sources, "-lm", "-o", output], cwd=folder,
                         capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 0, run.stderr
    return folder / output


def run_lines(binary: Path, values: np.ndarray) -> np.ndarray:
    """Feed one value per line on stdin; read one estimate per line."""
    text = "\n".join(repr(float(v)) for v in values) + "\n"
    run = subprocess.run([str(binary)], input=text, capture_output=True, text=True,
                         timeout=120, check=True)
    return np.array(run.stdout.split(), dtype=float)
