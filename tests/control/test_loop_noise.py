"""Sensor and process noise in the loop (issue 14 item 10)."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from hystkit import control as hc
from hystkit.cli import main

SIGNALS = ("y", "s", "y_hat", "s_hat", "e", "u", "y_hat_plant")


@pytest.fixture(scope="module")
def models() -> hc.SensorModels:
    return hc.setup_loop(hc.LoopSetup("direct")).models  # the CLI's default, kept on disk


@pytest.fixture(scope="module")
def loop(models) -> hc.ControlLoop:
    return hc.build_loop("weighting", models)


def _signals(result: hc.ExperimentResult) -> dict:
    return {(label, k): getattr(r, k) for label, r in result.cases.items() for k in SIGNALS}


def test_parse_noise():
    assert hc.parse_noise("sensor=1e-3,process=0.05,seed=7") == hc.NoiseSpec(1e-3, 0.05, 7)
    assert hc.parse_noise("process=2") == hc.NoiseSpec(0.0, 2.0, 0)
    for bad, fragment in (("sensor", "expected"), ("speed=1", "expected"),
                          ("sensor=1,sensor=2", "twice"), ("sensor=-1", ">= 0"),
                          ("sensor=x", "not a number"), ("seed=1.5", "not a number")):
        with pytest.raises(ValueError, match=fragment):
            hc.parse_noise(bad)


@pytest.mark.parametrize("name", ["sine", "disturbance"])
def test_zero_noise_is_the_noise_free_run_bit_for_bit(loop, name):
    quiet = hc.run_experiment(name, loop)
    zero = hc.run_experiment(name, loop, hc.NoiseSpec(0.0, 0.0, 123))
    for key, value in _signals(quiet).items():
        assert_array_equal(_signals(zero)[key], value, err_msg=str(key))


def test_same_seed_same_run_other_seed_other_run(loop):
    spec = hc.NoiseSpec(1e-3, 0.05, 4)
    a = _signals(hc.run_experiment("sine", loop, spec))
    b = _signals(hc.run_experiment("sine", loop, spec))
    c = _signals(hc.run_experiment("sine", loop, hc.NoiseSpec(1e-3, 0.05, 5)))
    for key in a:
        assert_array_equal(a[key], b[key], err_msg=str(key))
    assert not np.array_equal(a[("sine", "y")], c[("sine", "y")])


@pytest.mark.parametrize("sd", [5e-4, 2e-3])
def test_noise_measured_in_the_sensor_signal_is_the_requested_one(loop, sd):
    spec = hc.NoiseSpec(sensor=sd, process=0.02, seed=11)
    resp = hc.run_experiment("sine", loop, spec).cases["sine"]
    drawn, _ = spec.draw(resp.r.size, 0)
    clean, _ = loop.sensor.simulate(resp.y, loop.ts)
    # what the loop's sensor signal holds beyond S_r(y) is exactly the drawn noise ...
    assert_allclose(resp.s - clean, drawn, rtol=0, atol=1e-12)
    # ... and its SD is the requested one: 19841 samples, SE of an SD = sd / sqrt(2 n) = 0.5 %;
    # 3 % is six standard errors
    assert_allclose(hc.measured_sensor_noise(loop, resp), sd, rtol=0.03)


def test_noisy_run_matches_the_plain_python_reference(loop):
    spec = hc.NoiseSpec(1e-3, 0.05, 2)
    resp = hc.run_experiment("sine", loop, spec).cases["sine"]
    sensor, process = spec.draw(resp.r.size, 0)
    ref = hc.simulate_loop_reference(loop, resp.r, d_in=process, noise=sensor)
    for key in SIGNALS:
        assert_allclose(getattr(resp, key), getattr(ref, key), rtol=1e-9, atol=1e-12,
                        err_msg=key)


def test_noise_study_runs_four_variants(loop):
    spec = hc.NoiseSpec(1e-3, 0.05, 1)
    rows = hc.noise_study("sine", loop, spec, hc.DisturbanceObserver(20.0))
    assert [(r["noise"], r["dob"]) for r in rows] == [(False, False), (False, True),
                                                      (True, False), (True, True)]
    for r in rows:
        assert r["bounded"]
        if r["noise"]:
            assert_allclose(r["sensor_noise_sd"], 1e-3, rtol=0.03)
        else:
            assert r["sensor_noise_sd"] < 1e-12
    # the DOB run without noise is the plain experiment with that DOB
    with_dob = hc.run_experiment("sine", replace(loop, dob=hc.DisturbanceObserver(20.0)))
    assert rows[1]["e_p_rms"] == with_dob.metrics()["e_p_rms"]


def test_cli_noise_writes_the_study(capsys, tmp_path):
    out = tmp_path / "noisy"
    capsys.readouterr()
    code = main(["control", "--scheme", "direct", "--experiment", "sine", "--noise",
                 "sensor=1e-3,process=0.05,seed=3", "--out", str(out)])
    stdout, err = capsys.readouterr()
    assert code == 0, err
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["noise"] == {"sensor_sd": 1e-3, "process_sd_n": 0.05, "seed": 3}
    rows = metrics["noise_study"]["rows"]
    assert len(rows) == 4 and all(r["bounded"] for r in rows)
    # the main run is the noisy one with the loop's own DOB setting (off)
    noisy_off = next(r for r in rows if r["noise"] and not r["dob"])
    assert noisy_off["e_p_rms"] == metrics["e_p_rms"]
    assert "noise study" in stdout


def test_cli_bad_noise_is_one_line(capsys, tmp_path):
    capsys.readouterr()
    code = main(["control", "--scheme", "direct", "--experiment", "sine", "--noise",
                 "sensor=-1", "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--noise" in err[0] and ">= 0" in err[0]
