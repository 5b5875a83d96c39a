"""Polynomial-mPL blocks in the loop and paper 9.2's table II as the "real" sensor ``S_r``."""

from __future__ import annotations

import json

import control as ct
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from hystkit import control as hc
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.models import mpl_poly
from hystkit.models.mpl_poly import PAPER_9_2_TABLE_II, paper_9_2_params
from hystkit.sensors import simulate_experiment

from ..cli_support import run_cli

TS = hc.TS


@pytest.fixture(scope="module")
def poly_models() -> hc.SensorModels:
    # the document's protocol: S_r = table II noise column, models fitted on its sine response
    return hc.fit_sensor_models(sensor=hc.table_ii_sensor("noise"), training="loop",
                                model_cells=3)


def _poly_compensator(column: str = "sine") -> hc.SensorBlock:
    """Another table II column as a direct poly compensator: normalised sensor -> 3 mm."""
    return hc.SensorBlock(mpl_poly.MplPolyStructure(1, 0.025),
                          paper_9_2_params(PAPER_9_2_TABLE_II[column]), False, 0.0, 1.0, 0.0,
                          3e-3, name="table II compensator")


def _reference(n: int) -> np.ndarray:
    t = np.arange(n) * TS
    return hc.sine_reference(n) + 1e-3 * np.clip(t - 0.3, 0, 1) ** 2


def _loops(poly_models):
    return {
        "direct": hc.build_loop("direct", poly_models),
        "weighting+dob": hc.build_loop("weighting", poly_models,
                                       dob=hc.DisturbanceObserver(25.0)),
        "poly compensator": hc.tare(hc.ControlLoop("direct", poly_models.sensor,
                                                   hc.DOCUMENT_PID_DIRECT,
                                                   compensator=_poly_compensator())),
    }


@pytest.mark.parametrize("name", ["direct", "weighting+dob", "poly compensator"])
def test_kernel_matches_reference_with_poly_blocks(poly_models, name):
    loop = _loops(poly_models)[name]
    n = 1200
    rng = np.random.default_rng(5)
    r = _reference(n)
    extra = {"d_in": 0.05 * rng.standard_normal(n), "noise": 1e-4 * rng.standard_normal(n)}
    fast = hc.simulate_loop(loop, r, **extra)
    slow = hc.simulate_loop_reference(loop, r, **extra)
    assert fast.bounded and slow.bounded
    # Newton (kernel) and brentq (reference) both solve g(z) = s to round-off
    for key, scale in (("y", 1e-3), ("s", 1.0), ("y_hat", 1e-3), ("e", 1e-3), ("u", 10.0)):
        assert_allclose(getattr(fast, key), getattr(slow, key), rtol=0, atol=1e-11 * scale)
    assert_allclose(fast.state.to_vector(), slow.state.to_vector(), rtol=1e-9, atol=1e-13)


@pytest.mark.parametrize("name", ["weighting+dob", "poly compensator"])
def test_split_run_equals_whole_run_with_poly_blocks(poly_models, name):
    loop = _loops(poly_models)[name]
    r = _reference(2500)
    whole = hc.simulate_loop(loop, r)
    first = hc.simulate_loop(loop, r[:987])
    second = hc.simulate_loop(loop, r[987:], state=first.state)
    for key in ("y", "s", "y_hat", "e", "u"):
        assert_array_equal(np.concatenate([getattr(first, key), getattr(second, key)]),
                           getattr(whole, key))
    assert_array_equal(second.state.to_vector(), whole.state.to_vector())


LINEAR = mpl_poly.MplPolyParams(f=[[0.0, 50.0, 0.0, 1e-12]], g=[0.0, 2.0, 0.0, 0.0],
                                w=[1.0, -0.4], v_b=0.0)


@pytest.mark.parametrize("params", [LINEAR, paper_9_2_params(PAPER_9_2_TABLE_II["noise"])],
                         ids=["f and g linear", "table II noise"])
def test_poly_sensor_with_its_exact_inverse_reduces_to_the_linear_loop(params):
    """A poly sensor and the same model run backwards as compensator: y_hat = y, so scheme (a)
    is the linear loop of eq. 7.1-7.2 (python-control's closed form)."""
    structure = mpl_poly.MplPolyStructure(1, 0.025)
    sensor = hc.SensorBlock(structure, params, False, 0.0, 3e-3, 0.0, 1.0, name="S_r")
    comp = hc.SensorBlock(structure, params, True, 0.0, 1.0, 0.0, 3e-3, name="exact inverse")
    loop = hc.ControlLoop("direct", sensor, hc.DOCUMENT_PID_DIRECT, compensator=comp)
    r = _reference(round(2.0 / TS))
    res = hc.simulate_loop(loop, r)
    num, den = hc.DOCUMENT_PID_DIRECT.transfer_coefficients(TS)
    a, b, c = hc.plant_matrices(hc.MASS, TS)
    open_loop = ct.ss(a, b.reshape(2, 1), c.reshape(1, 2), 0, TS) * ct.tf2ss(ct.tf(num, den, TS))
    y_ref = ct.forced_response(ct.feedback(open_loop, 1), np.arange(r.size) * TS, r).outputs
    assert res.bounded
    assert_allclose(res.y_hat, res.y, rtol=0, atol=1e-12)
    assert_allclose(res.y, y_ref, rtol=0, atol=1e-9 * np.max(np.abs(r)))


def test_linear_poly_sensor_in_scheme_b_is_the_linear_loop_with_its_dynamics():
    structure = mpl_poly.MplPolyStructure(1, 0.025)
    sensor = hc.SensorBlock(structure, LINEAR, False, 0.0, 3e-3, 0.0, 1.0, name="S_r")
    model = hc.SensorBlock(structure, LINEAR, False, 0.0, 3e-3, 0.0, 1.0, name="S_m")
    gain = 1.0 / hc.SensorBlock.step(sensor, sensor.rest_state(3e-3), 3e-3, TS)[0] * 3e-3
    loop = hc.ControlLoop("weighting", sensor, hc.DOCUMENT_PID_WEIGHTING, model=model,
                          sensor_gain=gain)
    r = _reference(round(2.0 / TS))
    res = hc.simulate_loop(loop, r)
    # S(z): x+ = (1 - 50 Ts) x + 50 Ts u, s = 2 (u - 0.4 x) / 3 mm
    k = 50.0 * TS
    s_tf = ct.ss([[1 - k]], [[k]], [[-0.8 / 3e-3]], [[2.0 / 3e-3]], TS)
    num, den = hc.DOCUMENT_PID_WEIGHTING.transfer_coefficients(TS)
    a, b, c = hc.plant_matrices(hc.MASS, TS)
    fwd = (ct.ss(a, b.reshape(2, 1), c.reshape(1, 2), 0, TS) * ct.tf2ss(ct.tf(num, den, TS))
           * gain * s_tf)
    y_ref = ct.forced_response(ct.feedback(fwd, 1), np.arange(r.size) * TS, r).outputs
    assert res.bounded
    assert_allclose(res.y, y_ref, rtol=0, atol=1e-8 * np.max(np.abs(r)))


def test_poly_linearisation_matches_finite_differences():
    for block, u0 in ((hc.table_ii_sensor("noise"), 1e-3), (_poly_compensator(), 0.2)):
        x0 = block.rest_state(u0) + 0.05
        a, b, c, d = block.linearise(x0, u0, TS)
        h = 1e-7 * block.in_scale
        (y_p, x_p), (y_m, x_m) = block.step(x0, u0 + h, TS), block.step(x0, u0 - h, TS)
        assert_allclose((x_p - x_m) / (2 * h), b, rtol=1e-5)
        assert_allclose((y_p - y_m) / (2 * h), d, rtol=1e-5)
        (y_p, x_p), (y_m, x_m) = block.step(x0 + 1e-7, u0, TS), block.step(x0 - 1e-7, u0, TS)
        assert_allclose((x_p - x_m) / 2e-7, a[:, 0], rtol=1e-5)
        assert_allclose((y_p - y_m) / 2e-7, c[0], rtol=1e-5)


def test_table_ii_sensor_is_the_inverse_of_its_column():
    s_r = hc.table_ii_sensor("noise")
    t = np.arange(0, 10, 0.025)
    p = 3e-3 * np.sin(np.pi * t)
    s, _ = s_r.simulate(p, 0.025)
    p_back, _ = mpl_poly.simulate(s_r.structure, s_r.params, s, s_r.rest_state(p[0]))
    assert_allclose(p_back * 3e-3, p, rtol=0, atol=1e-12)  # the column maps s back to p
    assert 0.8 < np.max(np.abs(s)) < 1.5  # the normalised sensor spans about +-1


def test_sensor_outside_the_branch_stops_the_loop_not_nan():
    loop = hc.tare(hc.ControlLoop("direct", hc.table_ii_sensor("noise"), hc.DOCUMENT_PID_DIRECT,
                                  compensator=_poly_compensator()))
    res = hc.simulate_loop(loop, np.full(200, 0.05))  # 50 mm: beyond g's monotone range
    assert not res.bounded and res.stop_reason.startswith(("sensor", "control", "plant"))
    assert np.all(np.isfinite(res.y))


def test_cli_table_ii_sensor(capsys, tmp_path):
    out = tmp_path / "t2"
    code, _, err = run_cli(capsys, "control", "--scheme", "weighting", "--sensor",
                         "table-ii-noise", "--experiment", "sine", "--out", out)
    assert code == 0, err
    config = json.loads((out / "config.json").read_text())
    assert config["sensor"] == "table-ii-noise" and config["models"]["training"] == "loop"
    assert "table II, noise" in config["models"]["sensor_source"]
    assert json.loads((out / "metrics.json").read_text())["bounded"]


def test_cli_runs_a_saved_mpl_poly_compensator(capsys, tmp_path):
    model = tmp_path / "poly.json"
    save_compensator(fit_compensator(simulate_experiment("sine", 4), 1, model="mpl-poly"), model)
    out = tmp_path / "own"
    code, _, err = run_cli(capsys, "control", "--scheme", "direct", "--experiment", "sine",
                        "--compensator", model, "--out", out)
    assert code == 0, err
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["bounded"] and metrics["e_p_max"] < 5e-3
