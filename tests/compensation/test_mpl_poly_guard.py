"""mpl-poly's domain bounds its runs only loosely; the compensator's guard keeps runaways out.

mpl-poly's parameter domain must hold the fit's box (``docs/models/mpl_poly.md``), so inside it
a cell may rest far from the data (linear coefficient 0: a double root at 0, the stable rest
point at -1e5) and the output from ``|u| <= 0.3`` reaches ~1e25: finite and within
``output_bound``, the domain's only promise, but no position. ``Compensator.estimate`` refuses any estimate beyond
``MAX_NORMALISED`` times the training range, and the CLI writes nothing.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.compensation import fit_compensator
from hystkit.compensation._compensator import MAX_NORMALISED
from hystkit.compensation._model_file import save_compensator
from hystkit.errors import FitDivergedError
from hystkit.io import write_recording
from hystkit.models.mpl_poly import model as mp
from hystkit.sensors import simulate_experiment

# c1 = 0: the cubic v^2 (10 + 1e-4 v) has a double root at 0 (semi-stable) and its stable
# rest point at -1e5, where the cell starts; z ~ 1e5 and g(z) ~ 1e15 .. 1e26
RUNAWAY = mp.MplPolyParams(f=[[0.0, 0.0, 10.0, 1e-4]], g=[0.0, 1.0, 0.0, 1.0], w=[1.0, 1.0])


def test_the_domain_accepts_a_runaway_that_stays_within_its_bound() -> None:
    structure = mp.MplPolyStructure(n_cells=1, dt=0.025)
    u = 0.3 * np.sin(np.arange(2000) * 0.05)
    y, _ = mp.simulate(structure, RUNAWAY, u)
    assert np.all(np.isfinite(y))
    assert np.max(np.abs(y)) <= mp.output_bound(structure, RUNAWAY, 0.3)
    assert np.max(np.abs(y)) > 1e20  # what the loose bound allows: the reason for the guard


@pytest.fixture(scope="module")
def runaway(tmp_path_factory: pytest.TempPathFactory):
    rec = simulate_experiment("sine", 1)
    comp = dataclasses.replace(fit_compensator(rec, model="mpl-poly", diagnose=False),
                               params=RUNAWAY)
    return comp, rec


def test_the_compensator_refuses_the_runaway_estimate(runaway) -> None:
    comp, rec = runaway
    beyond = re.escape(f"beyond {MAX_NORMALISED:g} times the training range")
    with pytest.raises(FitDivergedError, match=rf"column 'sensor', sample \d+: .*{beyond}"):
        comp.estimate(rec)


def test_compensate_and_evaluate_write_nothing(runaway, tmp_path: Path, capsys) -> None:
    comp, rec = runaway
    model, data = tmp_path / "runaway.json", tmp_path / "val.csv"
    save_compensator(comp, model)
    write_recording(rec, data)
    before = sorted(tmp_path.iterdir())
    for argv in (["compensate", model, data, "--out", tmp_path / "out.csv"],
                 ["evaluate", model, data, "--json", tmp_path / "scores.json"]):
        assert main([str(a) for a in argv]) == 2
        err = capsys.readouterr().err
        assert "Traceback" not in err and "runaway.json" in err and "beyond" in err
    assert sorted(tmp_path.iterdir()) == before
