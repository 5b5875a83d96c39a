"""A recording too short for SINAD scores n/a with the reason, in evaluate, its JSON, the CLI
and the report (issue 25 item 2); a long one keeps its number and has no note."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.compensation import evaluate, fit_compensator
from hystkit.datasets import load_excerpt
from hystkit.sensors import simulate_experiment
from hystkit.studies._report_model import score_section

SINAD_KEYS = ("sinad_db", "linear_sinad_db", "sinad_db_oracle", "linear_sinad_db_oracle")


@pytest.fixture(scope="module")
def piezo():
    rec = load_excerpt("piezo_micromanipulator", "identification").to_recording()
    return fit_compensator(rec), rec


def test_a_short_recording_scores_sinad_na_with_the_reason(piezo):
    comp, rec = piezo
    scores = evaluate(comp, rec)
    assert scores["r2"] > 0.99  # a good estimate: n/a is about the record, not the model
    assert all(scores[key] is None for key in SINAD_KEYS)
    assert set(scores["notes"]) == set(SINAD_KEYS)
    for note in scores["notes"].values():
        assert note.startswith("SINAD n/a: ") and "too short for its frequency" in note
        assert f"of {rec.n_samples} samples" in note
    json.dumps(scores, allow_nan=False)
    html = score_section(comp, {"piezo": scores}).to_html()
    assert html.count("<td>n/a</td>") == 4  # model and line, deployable and oracle
    assert html.count("too short for its frequency") == 1


def test_a_long_recording_keeps_its_sinad_and_has_no_note():
    comp = fit_compensator(simulate_experiment("sine", 1), 1)
    scores = evaluate(comp, simulate_experiment("sine", 2))
    assert scores["notes"] == {}
    assert all(np.isfinite(scores[key]) for key in SINAD_KEYS)


def test_cli_evaluate_prints_the_reason_once_and_writes_it(tmp_path, capsys):
    data, model, out = tmp_path / "id.csv", tmp_path / "m.json", tmp_path / "scores.json"
    assert main(["datasets", "export", "piezo_micromanipulator", "--excerpt", "--variant",
                 "identification", "--out", str(data)]) == 0
    assert main(["fit", str(data), "--model", "mpl", "--out", str(model)]) == 0
    capsys.readouterr()
    assert main(["evaluate", str(model), str(data), "--json", str(out)]) == 0
    stdout = capsys.readouterr().out
    sinad_line = next(line for line in stdout.splitlines() if line.startswith("SINAD dB"))
    assert sinad_line.split()[2:] == ["n/a"] * 4
    assert stdout.count("too short for its frequency") == 1
    notes = json.loads(out.read_text())["notes"]
    assert set(notes) == set(SINAD_KEYS) and "too short" in notes["sinad_db"]
