"""Experiments of sec. 7.2-7.3, the document's qualitative findings, and ``hystkit control``."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit import control as hc
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.sensors import simulate_experiment

from ..cli_support import run_cli

matplotlib.use("Agg")  # figures are written; never open a window

TS = hc.TS
METRIC_KEYS = {"e_p_max", "e_p_mean", "e_p_rms", "tracking_rms", "bounded", "seconds"}


@pytest.fixture(scope="module")
def models() -> hc.SensorModels:
    # the CLI's default models (kept on disk): the CLI tests below read this fit instead of
    # repeating it (about 2 s each)
    return hc.setup_loop(hc.LoopSetup("direct")).models


def _one_error_line(err: str, *fragments: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hystkit: error: "), err
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


# --------------------------------------------------------------------------- references


def test_sine_reference_is_eq_7_3():
    r = hc.sine_reference(4000)
    t = np.arange(4000) * TS
    # 2 pi 0.5 t and pi t round differently: 1e-17 m
    assert_allclose(r, 0.003 * np.sin(np.pi * t), rtol=1e-12, atol=1e-17)


def test_cubic_trajectory_respects_the_bounds():
    r = hc.cubic_trajectory()
    v = np.diff(r) / TS
    a = np.diff(v) / TS
    # sec. 7.3.1: |v| <= 7.5 mm/s, |a| <= 0.15 m/s^2 (finite differences: one-sample slack)
    assert np.max(np.abs(v)) <= 7.5e-3 * (1 + 1e-3)
    assert np.max(np.abs(a)) <= 0.15 * (1 + 1e-2)
    assert np.max(np.abs(v)) > 0.95 * 7.5e-3  # and uses them: the long moves hit v_max
    assert r[0] == 0.0 and abs(r[-1]) < 1e-15


def test_experiment_cases():
    sizes = {name: len(hc.experiment_cases(name)) for name in hc.EXPERIMENTS}
    assert sizes == {"sine": 1, "frequency": 5, "amplitude": 5, "cubic": 1, "disturbance": 3}
    dist = hc.experiment_cases("disturbance")[2]
    t = np.arange(dist.r.size) * TS
    assert_allclose(dist.d_out[(t >= 1.7) & (t < 2.2)], 3e-3)
    assert np.all(dist.d_out[(t < 1.7) | (t >= 2.2)] == 0)
    with pytest.raises(ValueError, match="unknown experiment"):
        hc.experiment_cases("chirp")


# --------------------------------------------------------------------------- findings


def test_document_findings_for_direct_compensation(models):
    """Scheme (a): good at the trained sine, worse off it, unbounded at larger amplitude."""
    loop = hc.build_loop("direct", models)
    sine = hc.run_experiment("sine", loop).metrics()
    assert sine["bounded"] and sine["e_p_max"] < 1e-3  # the document's order: 6.94e-4 m
    freq = hc.run_experiment("frequency", loop).metrics()["cases"]
    assert freq["0.125 Hz"]["e_p_rms"] > 3 * freq["0.5 Hz"]["e_p_rms"]
    amp = hc.run_experiment("amplitude", loop).metrics()["cases"]
    assert amp["1 mm"]["bounded"] and amp["3 mm"]["bounded"]
    assert not amp["6 mm"]["bounded"]  # sec. 7.2: "output grows to infinity" for A > A_train
    assert amp["4.5 mm"]["e_p_max"] > 30 * amp["3 mm"]["e_p_max"]


def test_input_weighting_stays_bounded_where_direct_diverges(models):
    amp = hc.run_experiment("amplitude", hc.build_loop("weighting", models)).metrics()
    assert amp["all_bounded"]  # sec. 7.3: "still able to be responsive" at larger amplitude


def test_disturbance_metrics(models):
    res = hc.run_experiment("disturbance", hc.build_loop("direct", models)).metrics()
    cases = res["cases"]
    assert list(cases) == ["0 mm step", "1 mm step", "3 mm step"]
    assert cases["3 mm step"]["e_p_max"] >= 3e-3 - 1e-9  # the step itself, before any reaction
    for case in cases.values():
        assert case["e_p_max_after"] < 1e-3  # recovered (sec. 7.3.2: both schemes recover)


# --------------------------------------------------------------------------- CLI


def test_cli_sine_writes_metrics_figures_and_config(capsys, tmp_path):
    out = tmp_path / "run"
    code, stdout, err = run_cli(capsys, "control", "--scheme", "direct", "--experiment", "sine",
                             "--bode", "--out", out)
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["bode.png", "config.json", "metrics.json",
                                                     "response.png"]
    metrics = json.loads((out / "metrics.json").read_text())
    assert METRIC_KEYS <= set(metrics) and METRIC_KEYS <= set(metrics["cases"]["sine"])
    assert metrics["document"]["e_p_max"] == 6.94e-4  # eq. 7.6, printed beside ours
    assert metrics["linear"]["crossover_hz"] > 15
    config = json.loads((out / "config.json").read_text())
    assert config["pid"] == {"kp": 545.0, "ti": 0.029, "td": 0.0573, "tf": 0.0,
                             "anti_windup": False, "source": "document"}
    assert "eq. 7.6" in stdout and "crossover" in stdout


def test_cli_sweep_writes_one_entry_and_figure_per_case(capsys, tmp_path):
    out = tmp_path / "sweep"
    code, _, err = run_cli(capsys, "control", "--scheme", "weighting", "--experiment",
                        "frequency", "--dob", "--dob-hz", "20", "--out", out)
    assert code == 0, err
    metrics = json.loads((out / "metrics.json").read_text())
    assert list(metrics["cases"]) == ["0.125 Hz", "0.25 Hz", "0.5 Hz", "1 Hz", "2 Hz"]
    assert metrics["dob"] is True
    for case in metrics["cases"].values():
        assert METRIC_KEYS <= set(case)
    names = {p.name for p in out.iterdir()}
    assert {"cases.png", "case_0.125_Hz.png", "case_2_Hz.png", "metrics.json"} <= names


def test_cli_never_overwrites_without_force(capsys, tmp_path):
    out = tmp_path / "once"
    assert run_cli(capsys, "control", "--scheme", "direct", "--bode", "--out", out)[0] == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    code, _, err = run_cli(capsys, "control", "--scheme", "direct", "--bode", "--out", out)
    assert code == 2
    _one_error_line(err, "already exists", "--force")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    code, _, err = run_cli(capsys, "control", "--scheme", "direct", "--bode", "--out", out,
                        "--force")
    assert code == 0, err


@pytest.mark.parametrize(("argv", "fragment"), [
    (["--scheme", "direct"], "--experiment"),
    (["--scheme", "sideways", "--bode"], "invalid choice"),
    (["--scheme", "direct", "--bode", "--dob-hz", "0"], "--dob-hz: must be > 0"),
    (["--scheme", "direct", "--bode", "--tune", "20", "95"], "--tune PM_DEG: must be < 90"),
])
def test_cli_bad_options_give_one_error_line(capsys, tmp_path, argv, fragment):
    code, _, err = run_cli(capsys, "control", *argv, "--out", tmp_path / "x")
    assert code == 2
    _one_error_line(err, fragment)
    assert not Path(tmp_path / "x" / "metrics.json").exists()


def test_cli_reports_an_unbounded_run_without_failing(capsys, tmp_path):
    out = tmp_path / "unstable"
    code, stdout, err = run_cli(capsys, "control", "--scheme", "direct", "--experiment", "sine",
                             "--pid", "-545", "0.029", "0.0573", "--out", out)
    assert code == 0, err
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["bounded"] is False and metrics["stop_time"] > 0
    assert "NO" in stdout and "stopped at t =" in stdout


def test_cli_runs_a_saved_compensator(capsys, tmp_path):
    model = tmp_path / "chirp.json"
    save_compensator(fit_compensator(simulate_experiment("chirp", 4), 1), model)
    out = tmp_path / "own"
    code, _, err = run_cli(capsys, "control", "--scheme", "direct", "--bode", "--compensator",
                        model, "--out", out)
    assert code == 0, err
    config = json.loads((out / "config.json").read_text())
    assert config["models"]["compensator_file"] == str(model)
    assert config["compensator_fit"]["training_source"] == "<virtual sensor: chirp, seed 4>"
