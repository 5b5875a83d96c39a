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


# A C program that runs an exported model's own ``model_rest`` / ``model_step`` on stdin's
# numbers and prints each output exactly (hex float)
_DRIVER = r"""#include <stdio.h>
#include "{name}.c"
int main(void)
{{
    static real x[N_CELLS];
    double value;
    int started = 0;
    while (scanf("%lf", &value) == 1) {{
        if (!started) model_rest(x, value);
        started = 1;
        printf("%a\n", model_step(x, value));
    }}
    return 0;
}}
"""


def model_steps_in_c(tmp_path: Path, compensator: Compensator, u: np.ndarray,
                     name: str = "exported_model") -> np.ndarray:
    """``model_rest`` at u[0], then ``model_step`` per sample, of the compensator's double C
    export, built with ``-std=c99 -ffp-contract=off`` (no fused multiply-add: the compiled
    model's arithmetic, bit for bit)."""
    from hystkit.export import c_files, make_plan

    cc = need("cc")
    plan = make_plan(compensator, name=name)
    for file_name, text in c_files(plan, double=True).items():
        (tmp_path / file_name).write_text(text)
    (tmp_path / "driver.c").write_text(_DRIVER.format(name=name))
    subprocess.run([cc, "-O2", "-std=c99", "-ffp-contract=off", "driver.c", "-lm", "-o",
                    "driver"], cwd=tmp_path, check=True, capture_output=True, text=True)
    out = subprocess.run([str(tmp_path / "driver")], input="".join(f"{float(v)!r}\n" for v in u),
                         capture_output=True, text=True, check=True).stdout.split()
    return np.array([float.fromhex(v) for v in out])

