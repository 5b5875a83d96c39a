"""Table 2.2 on the virtual sensor: the statistics against Python's own, and each repeat's RMSE
against a fit and a hand-computed RMSE of the same recordings."""

from __future__ import annotations

import json
import math
import statistics

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.compensation import fit_compensator
from hystkit.sensors import simulate_experiment
from hystkit.studies import DOCUMENT_TABLE_2_2, measure_table_2_2, rmse_statistics


def test_statistics_are_pythons_min_mean_and_sample_variance():
    values = [0.031, None, 0.027, 0.044, 0.0299]
    kept = [v for v in values if v is not None]
    stats = rmse_statistics(values)
    assert stats["n"] == 4
    assert stats["min_rmse"] == min(kept)
    assert stats["mean_rmse"] == pytest.approx(statistics.fmean(kept), rel=1e-15)
    assert stats["variance_rmse"] == pytest.approx(statistics.variance(kept), rel=1e-12)
    assert rmse_statistics([0.1])["variance_rmse"] is None  # one value has no spread


@pytest.fixture(scope="module")
def two_repeats() -> dict:
    return measure_table_2_2(2, seed=5, models=["mpl", "pl"])


def test_each_repeat_is_a_fit_on_its_training_seed_scored_by_hand(two_repeats):
    """Repeat r: a compensator fitted on seed 5 + 2r; its RMSE on the training and the test
    recording, computed here from the estimate and the training position scale."""
    for r, entry in enumerate(two_repeats["repeats"]):
        assert (entry["training_seed"], entry["test_seed"]) == (5 + 2 * r, 6 + 2 * r)
        train = simulate_experiment("noise", entry["training_seed"])
        test = simulate_experiment("noise", entry["test_seed"])
        comp = fit_compensator(train, None, model="mpl", diagnose=False)
        scale = comp.scaling.position_scale
        for where, rec in (("training", train), ("test", test)):
            rmse = math.sqrt(float(np.mean((rec.position - comp.estimate(rec)) ** 2))) / scale
            assert entry["models"]["mpl"][f"{where}_rmse"] == pytest.approx(rmse, rel=1e-9)


def test_rows_are_the_statistics_of_the_repeats(two_repeats):
    rows = {(r["model"], r["set"], r["centring"]): r for r in two_repeats["rows"]}
    assert len(rows) == 2 * 2 * 2  # models x sets x centrings
    for (model, where, centring), row in rows.items():
        suffix = "_oracle" if "oracle" in centring else ""
        values = [e["models"][model][f"{where}_rmse{suffix}"] for e in two_repeats["repeats"]]
        assert row["min_rmse"] == min(values)
        assert row["variance_rmse"] == pytest.approx(statistics.variance(values), rel=1e-12)
        document = DOCUMENT_TABLE_2_2.get(model, {}).get(where)
        assert (row["document_mean_rmse"] is None) == (document is None)
    # the repeats differ (fresh noise trajectories), so the variance is no artefact of one fit
    assert rows[("pl", "test", "fit (deployable)")]["variance_rmse"] > 0


def test_cli_quick_writes_the_table(tmp_path, capsys):
    out = tmp_path / "t22"
    assert main(["table", "2.2", "--quick", "--models", "mpl", "--out", str(out)]) == 0
    data = json.loads((out / "table_2_2.json").read_text())
    assert data["settings"]["repeats"] == 3 and len(data["repeats"]) == 3
    lines = (out / "table_2_2.csv").read_text().splitlines()
    assert len(lines) == 1 + len(data["rows"]) == 1 + 4
    assert "| mpl | test | fit (deployable) | 3 |" in capsys.readouterr().out
    assert main(["table", "2.2", "--models", "nope"]) == 2
    assert "unknown model(s) nope" in capsys.readouterr().err
