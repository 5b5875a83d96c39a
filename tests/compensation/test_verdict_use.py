"""Verdicts predict use (issue 24): a compensator called ``ok`` works on the run it is judged
on, one that works is not refused. Both directions on measured data (the MR damper and the
B(H) loops of the shared data, skipped where absent) and on the virtual sensor, through the
command line as a user meets them.

The corpus behind ``MIN_USABLE`` (36 train/test pairs, :mod:`hystkit.compensation._verdict`):
the compensators that work held out score R² 0.81-1.00; the failures that neither the
straight line nor the ranges catch score 0.19-0.73. The cases below are that corpus's edges:
the lowest good ones, the highest bad ones and the issue's MR damper case.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.cli._common import GUARD_EXIT
from hystkit.compensation import evaluate, fit_compensator
from hystkit.compensation._verdict import (
    FAR_MARGIN,
    MAX_OUTSIDE,
    MIN_EXPLAINED,
    MIN_USABLE,
    USE_STATUSES,
    pooled_verdict,
    use_verdict,
    verdict,
)
from hystkit.errors import InputError
from hystkit.io import Recording, write_recording
from hystkit.sensors import simulate_experiment
from hystkit.studies._guided import selection_status


def _shared(tmp_path_factory, dataset: str, variant: str) -> Path:
    from hystkit.datasets import load

    try:
        rec = load(dataset, variant).to_recording()
    except InputError as exc:
        pytest.skip(f"shared data absent: {exc}")
    folder = tmp_path_factory.mktemp("use")
    return write_recording(rec, folder / f"{variant}.csv")


def _decay_tail(tmp_path_factory) -> Path:
    """The virtual sensor's decay, last third: a small amplitude inside the sine's range."""
    decay = simulate_experiment("decay", 1)
    tail = slice(2 * decay.n_samples // 3, None)
    rec = Recording(time=decay.time[tail] - decay.time[tail][0], sensor=decay.sensor[tail],
                    position=decay.position[tail], source="decay tail")
    return write_recording(rec, tmp_path_factory.mktemp("use") / "decay_tail.csv")


def _sine(tmp_path_factory) -> Path:
    return write_recording(simulate_experiment("sine", 1),
                           tmp_path_factory.mktemp("use") / "sine1.csv")


RUNS = {
    "ferrite_H80": ("bh_loops", "MnZn_ferrite_H80"),
    "ferrite_H40": ("bh_loops", "MnZn_ferrite_H40"),
    "ferrite_H16": ("bh_loops", "MnZn_ferrite_H16"),
    "steel_H218": ("bh_loops", "M130-27s_GO_steel_H218.8"),
    "steel_H65": ("bh_loops", "M130-27s_GO_steel_H65.7"),
    "mr_5mm_3Hz": ("mr_damper", "5mm_3Hz_0.75A"),
    "mr_10mm_1Hz": ("mr_damper", "10mm_1Hz_0.75A"),
    "mr_10mm_1Hz_0.5A": ("mr_damper", "10mm_1Hz_0.5A"),
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Paths of the runs, written when first asked for (a missing data set skips only its
    cases)."""
    made: dict[str, Path] = {}

    def get(name: str) -> Path:
        if name not in made:
            made[name] = (_sine(tmp_path_factory) if name == "sine1"
                          else _decay_tail(tmp_path_factory) if name == "decay_tail"
                          else _shared(tmp_path_factory, *RUNS[name]))
        return made[name]
    return get


def _fit_and_evaluate(runs, tmp_path, capsys, train, test, model) -> tuple[int, dict, str]:
    path = tmp_path / "model.json"
    assert main(["fit", str(runs(train)), "--model", model, "--out", str(path)]) == 0, \
        capsys.readouterr().err
    scores = tmp_path / "scores.json"
    capsys.readouterr()
    code = main(["evaluate", str(path), str(runs(test)), "--json", str(scores)])
    return code, json.loads(scores.read_text()), capsys.readouterr().err


@pytest.mark.parametrize(("train", "test", "model"), [
    ("ferrite_H80", "ferrite_H40", "mpl-poly"),  # R² 0.96: a smaller loop inside the trained one
    ("steel_H218", "steel_H65", "mpl-poly"),  # 0.83, the line -0.14: the lowest measured good
    ("sine1", "decay_tail", "mpl"),  # 0.81: a small amplitude, inside the trained range
])
def test_a_compensator_that_works_held_out_is_ok(runs, tmp_path, capsys, train, test, model):
    code, scores, err = _fit_and_evaluate(runs, tmp_path, capsys, train, test, model)
    assert code == 0 and scores["verdict"] == "ok", err
    assert scores["r2"] >= MIN_USABLE and scores["r2"] > scores["linear_r2"]
    assert scores["n_estimate_far_outside"] == 0 and scores["n_sensor_far_outside"] == 0


def test_the_mr_damper_beyond_its_trained_stroke_is_extrapolated(runs, tmp_path, capsys):
    """The issue's case: trained at 5 mm / 3 Hz, used at 10 mm / 1 Hz. The force stays inside
    its training range (the damper's force saturates), the estimate does not: about half of
    it lies far beyond the positions seen in training, and R² 0.14 (it was 'ok')."""
    code, scores, err = _fit_and_evaluate(runs, tmp_path, capsys, "mr_5mm_3Hz", "mr_10mm_1Hz",
                                          "mpl-poly")
    assert code == GUARD_EXIT and scores["verdict"] == "extrapolated"
    assert scores["n_sensor_far_outside"] == 0
    assert scores["n_estimate_far_outside"] > MAX_OUTSIDE * scores["n_samples"]
    assert MIN_EXPLAINED < scores["r2"] < MIN_USABLE and scores["r2"] > scores["linear_r2"]
    assert "of the estimates lie far outside the positions the model was trained on" in err


@pytest.mark.parametrize(("train", "test", "model"), [
    ("ferrite_H80", "ferrite_H16", "mpl-poly"),  # R² 0.19, the line -0.31 (it was 'ok')
    ("mr_10mm_1Hz", "mr_10mm_1Hz_0.5A", "mpl"),  # 0.73: another coil current (it was 'ok')
    ("mr_10mm_1Hz", "mr_5mm_3Hz", "mpl"),  # 0.58: another rate (it was 'ok')
])
def test_a_compensator_too_far_off_held_out_is_poor(runs, tmp_path, capsys, train, test,
                                                    model):
    """In range and above its straight line, yet its error is more than half the position's
    spread: not usable, whatever the line does."""
    code, scores, err = _fit_and_evaluate(runs, tmp_path, capsys, train, test, model)
    assert code == GUARD_EXIT and scores["verdict"] == "poor"
    assert MIN_EXPLAINED <= scores["r2"] < MIN_USABLE and scores["r2"] > scores["linear_r2"]
    assert scores["n_estimate_far_outside"] == 0 and scores["n_sensor_far_outside"] == 0
    assert err.strip().splitlines()[-1].startswith("hystkit: evaluate: poor: ")


def test_a_fit_that_cannot_follow_its_own_data_is_poor(tmp_path, capsys):
    """A sensor whose noise is as large as its signal: one mPL cell explains about half of
    the position in training; the fit is refused as poor, with what to try."""
    rec = simulate_experiment("sine", 1)
    rng = np.random.default_rng(5)
    noisy = Recording(time=rec.time, position=rec.position, source="noisy",
                      sensor=rec.sensor + np.std(rec.sensor) * rng.normal(size=rec.n_samples))
    data = write_recording(noisy, tmp_path / "noisy.csv")
    code = main(["fit", str(data), "--model", "mpl", "--out", str(tmp_path / "m.json")])
    out, err = capsys.readouterr()
    assert code == GUARD_EXIT and "hystkit: fit poor" in err
    info = json.loads((tmp_path / "m.json").read_text())["fit"]
    assert info["status"] == "poor"
    assert MIN_EXPLAINED <= info["training_r2"] < MIN_USABLE
    assert out.strip().splitlines()[-1].startswith("next: try --model auto")


def test_evaluate_counts_what_the_verdict_judges():
    """The far-outside counts of evaluate are the compensator's own masks at FAR_MARGIN."""
    sine1, sine2 = simulate_experiment("sine", 1), simulate_experiment("sine", 2)
    comp = fit_compensator(sine1, 1, diagnose=False)
    big = Recording(time=sine2.time, sensor=3 * sine2.sensor, position=3 * sine2.position,
                    source="big")
    scores = evaluate(comp, big)
    estimate = comp.estimate(big)
    assert scores["far_margin"] == FAR_MARGIN
    assert scores["n_sensor_far_outside"] == int(comp.sensor_outside(big, FAR_MARGIN).sum()) > 0
    assert scores["n_estimate_far_outside"] == int(
        comp.estimate_outside(estimate, FAR_MARGIN).sum()) > 0
    assert use_verdict(scores, "big") == verdict(
        scores["r2"], scores["linear_r2"], "big",
        scores["n_sensor_far_outside"] / scores["n_samples"],
        scores["n_estimate_far_outside"] / scores["n_samples"])


@pytest.mark.parametrize(("args", "status"), [
    ((MIN_USABLE, 0.0), "ok"), ((np.nextafter(MIN_USABLE, 0), 0.0), "poor"),
    ((MIN_EXPLAINED, 0.0), "poor"), ((np.nextafter(MIN_EXPLAINED, 0), 0.0), "no_signal"),
    ((0.5, 0.6), "worse_than_line"),  # the line first: its own message says more
    ((0.99, 0.9, None, MAX_OUTSIDE), "ok"),
    ((0.99, 0.9, None, np.nextafter(MAX_OUTSIDE, 1)), "extrapolated"),
    ((0.5, 0.0, 0.0, 0.5), "extrapolated"),  # out of range explains a poor score
    ((0.05, 0.0, 0.0, 0.5), "no_signal"),
    ((None, 0.5, 0.9, 0.9), "undetermined"),
])
def test_the_order_and_edges_of_the_rules(args, status):
    found, message = verdict(args[0], args[1], "held-out", *args[2:])
    assert found == status and status in USE_STATUSES
    assert "held-out" in message


def test_a_verdict_over_several_runs_pools_their_samples():
    """batch's validation runs: the mean R² of each run, the far-outside shares over all
    samples (a short run far outside weighs what its samples weigh)."""
    inside = {"r2": 0.95, "linear_r2": 0.9, "n_samples": 900, "n_sensor_far_outside": 0,
              "n_estimate_far_outside": 0}
    short = {**inside, "n_samples": 100, "n_estimate_far_outside": 100}
    assert pooled_verdict([inside, short], "runs")[0] == "ok"  # 100 of 1000: 10 %
    assert pooled_verdict([inside, {**short, "n_estimate_far_outside": 101,
                                    "n_samples": 101}], "runs")[0] == "extrapolated"
    assert pooled_verdict([inside, {**short, "r2": 0.5}], "runs")[0] == "worse_than_line"
    unknown = {**short, "n_sensor_far_outside": None, "n_estimate_far_outside": None}
    assert pooled_verdict([inside, unknown], "runs") == verdict(0.95, 0.9, "runs")


def _row(cv_r2: float, cv_line: float, status: str) -> dict:
    return {"cv_r2": cv_r2, "cv_linear_r2": cv_line, "verdict": status, "guard_failed": None}


@pytest.mark.parametrize(("rows", "status"), [
    ([_row(0.5, 0.3, "poor"), _row(0.6, 0.3, "poor")], "poor"),
    ([_row(0.05, 0.0, "no_signal"), _row(0.5, 0.0, "poor")], "poor"),
    ([_row(0.05, 0.0, "no_signal")], "no_signal"),
    ([_row(0.5, 0.8, "worse_than_line")], "worse_than_line"),  # the line would do
])
def test_a_selection_without_a_usable_candidate_says_why(rows, status):
    result = {"winner": None, "ranking": rows, "skipped": []}
    assert selection_status(result) == status
