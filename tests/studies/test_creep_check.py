"""Creep check: the sensor signal's creep against the virtual sensor's own creep term, and the
compensators' creep error against the same with the creep term switched off."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.sensors import VirtualSensor
from hystkit.studies import CreepPlan, creep_experiment, creep_trajectory, hold_levels

# 200 s holds: past five of the slowest Prony time constants (150 s), with time left over
PLAN = CreepPlan(hold_seconds=200.0)


@pytest.fixture(scope="module")
def with_creep() -> dict:
    return creep_experiment(PLAN, models=("mpl", "pl"))


@pytest.fixture(scope="module")
def without_creep() -> dict:
    sensor = VirtualSensor()
    no_creep = replace(sensor, prony_fractions=(0.0,) * len(sensor.prony_fractions))
    return creep_experiment(PLAN, models=("mpl", "pl"), sensor=no_creep)


def test_trajectory_holds_its_levels():
    t, x, holds = creep_trajectory(PLAN, 400.0)
    assert t[-1] == pytest.approx(PLAN.rest_seconds + 3 * (PLAN.ramp_seconds
                                                           + PLAN.hold_seconds))
    for hold in holds:
        inside = (t >= hold["ramp_end"]) & (t <= hold["end"])
        assert np.all(x[inside] == hold["level"])
        before, at_a, levels = hold_levels(t, x, hold, PLAN.settle_seconds)
        assert before == hold["before"] and at_a == hold["level"]
        assert all(v == hold["level"] for v in levels.values())


def test_sensor_creep_is_the_virtual_sensors_creep_term(with_creep):
    """The recorded dR1/R1 - dR2/R2 creeps as the network strain's Prony part does.

    Tolerance: R = R0 exp(gamma m) bends relative increments by up to gamma m / 2 = 4.6 % at
    2 mm (gamma 14, m <= 0.0066), partly cancelling between the two gauges; temperature and
    noise add ~0.3 % of the step.
    """
    for row in with_creep["rows"]:
        if row["after_s"] >= 10:  # before that the creep is a few % and noise dominates
            assert row["sensor_creep_pct"] == pytest.approx(row["physics_creep_pct"], rel=0.05)
    assert all(h["physics_creep_pct"] > 15 for h in with_creep["summary"])


def test_without_the_creep_term_nothing_creeps(without_creep):
    for hold in without_creep["summary"]:
        assert hold["physics_creep_pct"] == pytest.approx(0.0, abs=1e-9)  # exactly none
        assert abs(hold["sensor_creep_pct"]) < 0.5  # temperature drift, noise


def test_creep_error_comes_from_the_sensors_creep_term(with_creep, without_creep):
    """Each compensator's creep error at the end of a hold: no more than the sensor's own creep
    (neither fitted on a 200 s noise run models a 30 s retardation, nor adds creep), and most of
    it disappears when the sensor's creep term is switched off."""
    for hold, control in zip(with_creep["summary"], without_creep["summary"], strict=True):
        for name in ("mpl", "pl"):
            error = hold[f"{name}_creep_error_pct"]
            assert 0 < error < 1.1 * hold["physics_creep_pct"], (name, hold["hold"])
            assert abs(control[f"{name}_creep_error_pct"]) < 0.25 * error, (name, hold["hold"])
            assert hold[f"{name}_creep_error_mm"] == pytest.approx(error / 100 * hold["step_mm"])


def test_long_holds_add_no_creep_in_the_virtual_sensor(with_creep):
    """The sensor's creep is exponential: after five of its slowest time constants (150 s),
    what a Prony term f_i can still add is at most f_i exp(-150 / tau_i) of the imposed step,
    while the network strain made at least its instant part c = 1 - sum f - sum w of the step
    by t_a (every part moves the step's way). So the late creep is below
    100 sum_i f_i exp(-150 / tau_i) / c percent."""
    sensor = VirtualSensor()
    late = with_creep["sensor"]["late_after_s"]
    assert late == 5 * max(sensor.prony_taus)
    instant = 1 - sum(sensor.prony_fractions) - sum(sensor.play_weights)
    bound = 100 * sum(f * np.exp(-late / tau) for f, tau in
                      zip(sensor.prony_fractions, sensor.prony_taus, strict=True)) / instant
    for hold in with_creep["summary"]:
        assert 0 < hold["late_physics_creep_pct"] < bound
        assert hold["late_physics_creep_pct"] < hold["physics_creep_pct"] / 100


def test_cli_quick_writes_creep_files(tmp_path, capsys):
    out = tmp_path / "creep"
    assert main(["creep", "--quick", "--out", str(out)]) == 0
    data = json.loads((out / "creep.json").read_text())
    assert set(data["fits"]) == {"mpl", "pl"}
    header = (out / "creep.csv").read_text().splitlines()[0].split(",")
    assert {"physics_creep_pct", "sensor_creep_pct", "mpl_creep_error_pct",
            "pl_creep_error_pct"} <= set(header)
    assert "creep term" in capsys.readouterr().out
    assert main(["creep", "--hours", "0"]) == 2
