"""The export contract over the registry: every family either exports (its ``export.py``: the C
compiles with the strict flags and reproduces the compensator's own run) or is refused with its
declared reason, on one line (issue 28, item 1: a family is one folder, export included).

Each family runs from its documented parameter domain (``random_params``), so a family added
later is checked with no edit here.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.compensation import (
    Compensator,
    LinearBaseline,
    prepare_training_data,
    save_compensator,
)
from hystkit.errors import HystkitError, InputError
from hystkit.export import c_files, make_plan, matlab_files
from hystkit.models import FAMILIES, get_family, register, unregister
from hystkit.sensors import simulate_experiment

from ..export.export_support import compile_c, run_lines

N_SAMPLES = 1500  # of the noise recording (both directions, several amplitudes)
_MATLAB_FUNCTION = re.compile(r"^function\s+(?:\[[^\]]*\]\s*=\s*|\w+\s*=\s*)?(\w+)\s*\(",
                              re.MULTILINE)
# Subfunctions every MATLAB export defines (hystkit.export._matlab), beside the family's own.
_GENERIC_M_FUNCTIONS = {"body", "normalised", "model_load", "model_rest", "model_step",
                        "band_half"}

_HARNESS = """#include <stdio.h>
#include <stdlib.h>
#include "comp.h"
int main(void)
{
    char line[128];
    comp_state st;
    int started = 0;
    while (fgets(line, sizeof line, stdin) != NULL) {
        comp_real v = (comp_real)strtod(line, NULL);
        if (!started) { comp_init(&st, v); started = 1; }
        printf("%.17g\\n", (double)comp_step(&st, v));
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def recordings():
    train = simulate_experiment("sine", seed=1)
    val = simulate_experiment("noise", seed=2)
    return train, val.sensor[:N_SAMPLES]


def _compensator(name: str, mode: str, recordings) -> tuple[Compensator, np.ndarray]:
    """A compensator of family `name` from the first draw of its documented domain whose run on
    the recording stays finite, on the virtual sensor's conventions."""
    train, sensor = recordings
    family = get_family(name)
    conventions, s, _ = prepare_training_data([train], "fit")
    structure = family.make_structure(train.dt, family.default_size)
    for seed in range(40):
        comp = Compensator(
            structure=structure, params=family.random_params(structure,
                                                             np.random.default_rng(seed)),
            mode=mode, center="fit", baseline=LinearBaseline(1.0, 0.0), model=name,
            training_range=(float(np.min(s[0])), float(np.max(s[0]))),
            position_range=(float(np.min(train.position)), float(np.max(train.position))),
            **conventions)
        try:
            estimate = comp.estimate(sensor)  # an array: samples every structure.dt
        except (HystkitError, ValueError):
            continue
        if np.all(np.isfinite(estimate)):
            return comp, estimate
    raise AssertionError(f"no {name} {mode} compensator with a finite run in 40 draws")


_CASES = [(name, mode) for name in sorted(FAMILIES) for mode in ("direct", "inverse")
          if mode == "direct" or get_family(name).invert is not None]


@pytest.mark.parametrize(("name", "mode"), _CASES)
def test_every_family_exports_or_is_refused_with_its_reason(name, mode, recordings, tmp_path):
    family = get_family(name)
    comp, expected = _compensator(name, mode, recordings)
    refusal = family.export_refusal(mode == "inverse")
    if refusal:
        with pytest.raises(InputError) as err:
            make_plan(comp)
        assert "\n" not in str(err.value) and str(err.value).endswith(refusal)
        return
    for file, text in c_files(make_plan(comp, "comp"), double=True).items():
        if file != "example_main.c":
            (tmp_path / file).write_text(text)
    (tmp_path / "harness.c").write_text(_HARNESS)
    got = run_lines(compile_c(tmp_path), recordings[1])
    span = max(float(np.ptp(expected)), 1e-12)
    assert got.shape == expected.shape
    assert np.max(np.abs(got - expected)) <= 1e-9 * max(1.0, span)


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_a_translation_declares_its_matlab_subfunctions(name, recordings):
    """``Translation.m_functions`` are exactly the subfunctions its MATLAB defines beyond the
    generic ones: an export named like one of them is renamed, not shadowing it."""
    family = get_family(name)
    if family.export is None:
        pytest.skip(f"{name}: {family.export_refusal()}")
    modes = ["direct"] + (["inverse"] if family.invert is not None and family.export.inverse
                          else [])
    defined = set()
    for mode in modes:
        plan = make_plan(_compensator(name, mode, recordings)[0], "comp")
        for text in matlab_files(plan).values():
            defined |= set(_MATLAB_FUNCTION.findall(text))
    own = defined - _GENERIC_M_FUNCTIONS - {"comp", "comp_init", "comp_block", "comp_sync"}
    assert own == set(family.export.m_functions)
    comp = _compensator(name, "direct", recordings)[0]
    for subfunction in family.export.m_functions:
        with pytest.raises(InputError, match=f"e.g. '{subfunction}_model'"):
            make_plan(comp, subfunction)


@pytest.mark.parametrize("reason", ["the toy block is not translated yet", ""])
def test_a_family_without_export_is_refused_in_one_line(reason, recordings, tmp_path, capsys):
    """A registered family whose ``export`` is None: ``hystkit export`` refuses it with its
    declared ``no_export_reason`` (or, undeclared, one naming the file to write), nothing
    written."""
    base = type(get_family("mpl"))
    untranslated = type("Untranslated", (base,), {"name": "mpl-untranslated", "export": None,
                                                  "no_export_reason": reason})()
    register(untranslated)
    try:
        comp = _compensator("mpl-untranslated", "direct", recordings)[0]
        path = tmp_path / "m.json"
        save_compensator(comp, path)
        assert main(["export", str(path), "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        assert (reason or "export.py") in err
        assert "cannot export the mpl-untranslated direct compensator" in err
        assert not (tmp_path / "out").exists()
    finally:
        unregister("mpl-untranslated")
