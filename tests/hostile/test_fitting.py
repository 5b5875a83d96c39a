"""Hostile fitting data: short, constant, spiky or offset recordings get a clear outcome.

Data no model can be fitted to are refused before any family runs (exit 2, one line naming the
file and column, nothing written); ``compare`` and ``select`` report one family's failure in
its row (exit 3) and never abort with a traceback. Sizes are tiny: the file runs in seconds.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hystkit.cli._common import GUARD_EXIT
from hystkit.models import FAMILIES

from .conftest import snapshot


def _recording(good: dict[str, Path], folder: Path, name: str, n: int | None = None, *,
               position=None, sensor=None) -> Path:
    """The first `n` rows of the good fitting recording, columns optionally replaced by
    functions of the original column."""
    table = pd.read_csv(good["fit"]).iloc[:n]
    if position is not None:
        table["position"] = position(table["position"].to_numpy())
    if sensor is not None:
        table["sensor"] = sensor(table["sensor"].to_numpy())
    path = folder / name
    table.to_csv(path, index=False)
    return path


def _refused(cli, folder: Path, argv: list, *fragments: object) -> None:
    before = snapshot(folder)
    run = cli(*argv)
    assert run.code == 2, run.err
    run.error_line(*fragments)
    assert snapshot(folder) == before


@pytest.mark.parametrize("model", sorted(FAMILIES))
def test_two_rows_are_refused_for_every_family(cli, good, tmp_path, model):
    data = _recording(good, tmp_path, "two.csv", 2)
    _refused(cli, tmp_path, ["fit", data, "--model", model, "--out", tmp_path / "m.json"],
             "two.csv", "position", "2 samples", "at least")


def test_ten_rows_are_refused(cli, good, tmp_path):
    data = _recording(good, tmp_path, "ten.csv", 10)
    _refused(cli, tmp_path, ["fit", data, "--model", "mpl", "--out", tmp_path / "m.json"],
             "ten.csv", "10 samples")


def test_samples_per_parameter_checked_before_the_fit(cli, good, tmp_path):
    data = _recording(good, tmp_path, "short.csv", 60)  # mPL with 20 cells: 62 parameters
    _refused(cli, tmp_path, ["fit", data, "--cells", "20", "--out", tmp_path / "m.json"],
             "short.csv", "60 samples", "per parameter")


@pytest.mark.parametrize("column", ["position", "sensor"])
def test_constant_column_is_refused(cli, good, tmp_path, column):
    const = {column: lambda x: np.full_like(x, 0.3)}
    data = _recording(good, tmp_path, "flat.csv", 400, **const)
    _refused(cli, tmp_path, ["fit", data, "--model", "mpl", "--out", tmp_path / "m.json"],
             "flat.csv", f"column '{column}'", "constant")


def test_a_single_spike_is_refused(cli, good, tmp_path):
    def spike(x):
        return np.where(np.arange(x.size) == x.size // 2, 1.0, 0.0)

    data = _recording(good, tmp_path, "spike.csv", 400, position=spike, sensor=spike)
    _refused(cli, tmp_path, ["fit", data, "--model", "mpl", "--out", tmp_path / "m.json"],
             "spike.csv", "position", "spike")


def test_huge_offset_with_tiny_variation_is_refused(cli, good, tmp_path):
    data = _recording(good, tmp_path, "offset.csv", 400, position=lambda x: 1e90 + 1e-3 * x,
                      sensor=lambda x: 1e90 + 1e-3 * x)
    _refused(cli, tmp_path, ["fit", data, "--model", "mpl", "--out", tmp_path / "m.json"],
             "offset.csv", "position", "constant")


def test_variation_below_float_resolution_is_refused(cli, good, tmp_path):
    data = _recording(good, tmp_path, "offset.csv", 400, sensor=lambda x: 1e14 + x)
    _refused(cli, tmp_path, ["fit", data, "--model", "mpl", "--out", tmp_path / "m.json"],
             "offset.csv", "sensor", "resolves")


def test_a_large_offset_that_float_resolves_still_fits(cli, good, tmp_path):
    """1e10 mm offset, millimetres of motion: well within float64; the fit runs and passes."""
    data = _recording(good, tmp_path, "offset.csv", 400, position=lambda x: x + 1e10)
    run = cli("fit", data, "--model", "mpl", "--out", tmp_path / "m.json")
    run.clean()
    assert run.code == 0, run.err
    assert json.loads((tmp_path / "m.json").read_text())["fit"]["status"] == "ok"


def test_a_step_gets_a_clear_outcome(cli, good, tmp_path):
    """A clean two-level step: nothing to refuse, so the fit runs and its guards decide."""
    def step(x):
        return (np.arange(x.size) > x.size // 2).astype(float)

    data = _recording(good, tmp_path, "step.csv", 400, position=step, sensor=step)
    for model in ("mpl", "boucwen"):
        run = cli("fit", data, "--model", model, "--out", tmp_path / f"{model}.json")
        run.clean()
        assert run.code in (0, GUARD_EXIT), run.err


def test_compare_refuses_two_rows_in_one_line(cli, good, tmp_path):
    data = _recording(good, tmp_path, "two.csv", 2)
    _refused(cli, tmp_path, ["compare", data, good["val"], "--models", "mpl,boucwen",
                             "--out", tmp_path / "cmp"], "two.csv", "2 samples")


def test_compare_lists_a_family_the_data_are_too_short_for(cli, good, tmp_path):
    """40 samples: enough for the mPL, not for the 191 parameters of the Preisach grid; the
    table is still written, with the Preisach row failed, exit 3."""
    data = _recording(good, tmp_path, "short.csv", 40)
    run = cli("compare", data, good["val"], "--models", "mpl,preisach", "--out",
              tmp_path / "cmp")
    run.clean()
    assert run.code == GUARD_EXIT, run.err
    table = json.loads((tmp_path / "cmp" / "compare.json").read_text())
    table = table.get("models", table)
    assert "error" in table["preisach"] and "per parameter" in table["preisach"]["error"]
    assert "error" not in table["mpl"]
    assert "1 model(s) failed: preisach" in run.err


def test_select_refuses_a_constant_sensor_in_one_line(cli, good, tmp_path):
    data = _recording(good, tmp_path, "flat.csv", 400, sensor=lambda x: np.full_like(x, 2.0))
    _refused(cli, tmp_path, ["select", data, "--models", "mpl", "--out", tmp_path / "m.json"],
             "flat.csv", "sensor", "constant")


def test_select_shrinks_a_family_too_big_for_its_folds(cli, good, tmp_path):
    """Folds of 300 training samples: the Preisach default grid (191 numbers) cannot be fitted
    in them; it is tried at its largest admissible size instead of vanishing, and the exit
    code follows the winner."""
    data = _recording(good, tmp_path, "short.csv", 450)
    run = cli("select", data, "--models", "mpl,preisach", "--out", tmp_path / "m.json")
    run.clean()
    assert run.code == 0, run.err
    summary = json.loads((tmp_path / "m-selection" / "selection.json").read_text())
    preisach = [r for r in summary["ranking"] if r["model"] == "preisach"]
    assert preisach and all("error" not in r and 1 <= r["size"] < 20 for r in preisach)
    assert (tmp_path / "m.json").is_file()


def test_an_estimate_that_runs_away_is_refused_not_written(cli, good, tmp_path):
    """A sensor 1e8 times the training range: the estimate would be ~1e7 mm; compensate and
    evaluate refuse it naming the model file and the first sample, and write nothing."""
    table = pd.read_csv(good["val"])
    table["sensor"] *= 1e8
    data = tmp_path / "wild.csv"
    table.to_csv(data, index=False)
    _refused(cli, tmp_path, ["compensate", good["model"], data, "--out", tmp_path / "o.csv"],
             "wild.csv", "column 'sensor', sample", good["model"].name, "beyond")
    _refused(cli, tmp_path, ["evaluate", good["model"], data, "--json", tmp_path / "s.json"],
             "wild.csv", good["model"].name)


def test_evaluate_on_a_position_that_never_moves(cli, good, tmp_path):
    """R² and loop areas are undefined against a constant position: None in the JSON, not a
    crash; the run still reports the errors in mm."""
    table = pd.read_csv(good["val"])
    table["position"] = 1.0
    data = tmp_path / "still.csv"
    table.to_csv(data, index=False)
    run = cli("evaluate", good["model"], data, "--json", tmp_path / "s.json")
    run.clean()
    assert run.code == 0, run.err
    scores = json.loads((tmp_path / "s.json").read_text())
    assert scores["r2"] is None and scores["loop_area"] is None
    assert scores["e_rms_pct"] > 0


def test_compare_refuses_a_validation_recording_that_never_moves(cli, good, tmp_path):
    table = pd.read_csv(good["val"])
    table["position"] = 0.5
    val = tmp_path / "still.csv"
    table.to_csv(val, index=False)
    _refused(cli, tmp_path, ["compare", good["fit"], val, "--models", "mpl,boucwen", "--out",
                             tmp_path / "cmp"], "still.csv", "position", "constant")
