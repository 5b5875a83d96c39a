"""The virtual sensor's causal physics as a loop model (``--sensor virtual-physics``)."""

from __future__ import annotations

import dataclasses
import json

import matplotlib
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from hystkit import control as hc
from hystkit.cli import main
from hystkit.models import numerical_linearisation
from hystkit.sensors import VIRTUAL_PHYSICS as PHYS
from hystkit.sensors import VirtualSensor, physics_of
from hystkit.signals import excitation

matplotlib.use("Agg")

STRUCTURE, PARAMS = physics_of()  # 400 Hz, the simulator's internal rate


def _position(name: str = "noise", seed: int = 3) -> np.ndarray:
    return excitation(name, 400.0, seed)[1]


def _step_all(structure, params, u, x0):
    x, out = np.array(x0), []
    for v in u:
        y, x = PHYS.step(structure, params, x, v)
        out.append(y)
    return np.array(out), x


def test_block_matches_the_readable_step_sample_by_sample():
    u = _position()[:3000]
    block = PHYS.block(STRUCTURE, PARAMS)
    off = 4  # the block must respect its offset inside a larger loop state
    x0 = PHYS.rest_state(STRUCTURE, PARAMS, u[0])
    big = np.concatenate([np.full(off, 7.0), x0, [9.0]])
    xn = big.copy()
    x_ref = x0.copy()
    for v in u:
        y = block.step(block.body, big, xn, off, v)
        y_ref, x_ref = PHYS.step(STRUCTURE, PARAMS, x_ref, v)
        assert abs(y - y_ref) <= 1e-12
        assert_allclose(xn[off:off + block.n_state], x_ref, rtol=0, atol=1e-12)
        big, xn = xn, big
    assert_array_equal(big[:off], 7.0)  # the neighbours' state untouched
    assert big[-1] == 9.0
    assert block.n_state == x0.size


def test_simulate_is_the_step_loop_and_a_split_run_is_the_whole_run():
    u = _position()[:4000]
    y, x_end = PHYS.simulate(STRUCTURE, PARAMS, u)
    y_ref, x_ref = _step_all(STRUCTURE, PARAMS, u, PHYS.rest_state(STRUCTURE, PARAMS, u[0]))
    assert_allclose(y, y_ref, rtol=0, atol=1e-12)
    assert_allclose(x_end, x_ref, rtol=0, atol=1e-12)
    y1, x1 = PHYS.simulate(STRUCTURE, PARAMS, u[:1500])
    y2, x2 = PHYS.simulate(STRUCTURE, PARAMS, u[1500:], x1)
    assert_array_equal(np.concatenate([y1, y2]), y)
    assert_array_equal(x2, x_end)


@pytest.mark.parametrize("name", ["sine", "decay", "chirp", "noise"])
def test_agrees_with_the_simulators_internal_signal(name):
    # Independent path: the recording simulator's resistances before the filter, with what the
    # loop model leaves out switched off; dR/R relative to the unstrained gauges.
    sensor = VirtualSensor(temp_std=0.0, noise_rel=0.0, settle_drop=(0.0, 0.0))
    t, x = excitation(name, sensor.fs_internal, 5)
    r = sensor.resistances(x, t, np.random.default_rng(0))
    expected = r[0] / sensor.base_resistance[0] - r[1] / sensor.base_resistance[1]
    y, _ = PHYS.simulate(*physics_of(sensor), x)
    assert np.ptp(expected) > 0.1  # a real signal, not two zeros
    assert_allclose(y, expected, rtol=0, atol=1e-12)


def test_what_is_left_out_is_the_settling_drift_it_is_documented_as():
    # The default sensor with settling (noise and temperature off): the loop model differs by
    # no more than the settling factors' own change over the recording.
    sensor = VirtualSensor(temp_std=0.0, noise_rel=0.0)
    t, x = excitation("sine", sensor.fs_internal, 5)
    r = sensor.resistances(x, t, np.random.default_rng(0))
    simulated = r[0] / r[0, 0] - r[1] / r[1, 0]  # the sine starts at rest at 0
    y, _ = PHYS.simulate(*physics_of(sensor), x)
    age = sensor.age_hours + t / 3600
    bound = 0.0
    for g in range(2):
        settle = 1 + sensor.settle_drop[g] * np.exp(-age / sensor.settle_tau_hours)
        ratio = r[g] / r[g, 0] * settle[0] / settle  # settling divided out
        bound += np.max(np.abs(settle / settle[0] - 1)) * np.max(ratio)
    assert x[0] == 0.0
    gap = np.abs(y - simulated)
    assert 0 < np.max(gap) <= bound
    # the module docstring's figure: under 2e-7 over the loop's 5 s (signal span 0.33)
    assert np.max(gap[:round(5 * sensor.fs_internal)]) < 2e-7


@pytest.mark.parametrize("value", [0.0, 0.2, 1.5, -3.0])
def test_rest_state_is_a_fixed_point(value):
    x0 = PHYS.rest_state(STRUCTURE, PARAMS, value)
    y0, x1 = PHYS.step(STRUCTURE, PARAMS, x0, value)
    assert_array_equal(x1, x0)
    y, x_end = PHYS.simulate(STRUCTURE, PARAMS, np.full(50, value), x0)
    assert_array_equal(y, y0)
    assert_array_equal(x_end, x0)
    if value == 0.0:
        assert y0 == 0.0  # the reference: the unstrained gauges at rest


def test_rest_state_is_where_the_simulator_starts():
    # from virgin plays and Prony states at the first strain, as the simulator begins
    u = np.r_[np.full(10, 1.5), np.linspace(1.5, -1.0, 200)]
    y_rest, _ = PHYS.simulate(STRUCTURE, PARAMS, u)
    virgin = PHYS.rest_state(STRUCTURE, PARAMS, 0.0)
    p, j = len(STRUCTURE.prony_taus), len(STRUCTURE.play_radii)
    for g, sign in enumerate((1.0, -1.0)):
        virgin[g * (p + j):g * (p + j) + p] = sign * PARAMS.strain_per_mm * 1.5
    virgin[-2] = PARAMS.strain_per_mm * 1.5
    y_virgin, _ = PHYS.simulate(STRUCTURE, PARAMS, u, virgin)
    assert_allclose(y_rest, y_virgin, rtol=0, atol=1e-15)


def test_at_recomputes_the_prony_decays_and_keeps_the_step_response():
    fine = PHYS.at(STRUCTURE, STRUCTURE.dt / 5)
    assert fine == physics_of(dt=STRUCTURE.dt / 5)[0]
    assert_allclose(fine.decay, np.exp(-STRUCTURE.dt / 5 / np.array(STRUCTURE.prony_taus)),
                    rtol=1e-15)
    assert PHYS.at(fine, STRUCTURE.dt).decay == pytest.approx(STRUCTURE.decay, rel=1e-15)
    # The exact exponential update makes the response to a held (ZOH) input independent of dt
    # at the common sample times (the plays and the softening are rate independent).
    u = np.r_[0.0, np.full(1999, 2.0)]
    y, _ = PHYS.simulate(STRUCTURE, PARAMS, u)
    y_fine, _ = PHYS.simulate(fine, PARAMS, np.repeat(u, 5))
    assert_allclose(y_fine[::5], y, rtol=0, atol=1e-12)
    assert np.ptp(y[1:]) > 1e-3  # the step creeps: the Prony terms are at work


def test_analytical_linearisation_agrees_with_the_numerical_one():
    u = _position("sine")[:300]  # moving at 300 samples: travel and some plays
    _, x = PHYS.simulate(STRUCTURE, PARAMS, u[:-1])
    a, b, c, d = PHYS.linearise(STRUCTURE, PARAMS, x, u[-1])
    an, bn, cn, dn = numerical_linearisation(
        lambda xx, uu: PHYS.step(STRUCTURE, PARAMS, xx, uu), x, u[-1])
    # memory the input cannot reach, which the analytical form reports as neutral (zero rows)
    frozen = (np.abs(np.diag(an) - 1) < 1e-9) & (bn == 0)
    assert 0 < frozen.sum() < 2 * len(STRUCTURE.play_radii)  # some plays frozen, some moving
    assert_allclose(a[~frozen], an[~frozen], rtol=1e-6, atol=1e-9)
    assert_array_equal(a[frozen], 0.0)
    assert_allclose(b, bn, rtol=1e-6, atol=1e-9)
    assert_allclose(c, cn, rtol=1e-6, atol=1e-9)
    assert d == pytest.approx(dn, rel=1e-6)
    assert b[-1] != 0  # the travel is reachable while moving: its row stays an integrator


def test_linearisation_at_rest_has_the_same_impulse_response_without_marginal_poles():
    x0 = PHYS.rest_state(STRUCTURE, PARAMS, 0.0)
    a, b, c, d = PHYS.linearise(STRUCTURE, PARAMS, x0, 0.0)
    an, bn, cn, dn = numerical_linearisation(
        lambda xx, uu: PHYS.step(STRUCTURE, PARAMS, xx, uu), x0, 0.0)
    assert np.max(np.abs(np.linalg.eigvals(an))) == pytest.approx(1.0)  # frozen memory
    assert np.max(np.abs(np.linalg.eigvals(a))) < 1.0
    assert d == pytest.approx(dn, rel=1e-6)
    ak, akn = np.eye(a.shape[0]), np.eye(a.shape[0])
    for _ in range(50):  # Markov parameters C A^k B
        assert c @ ak @ b == pytest.approx(cn @ akn @ bn, rel=1e-6, abs=1e-12)
        ak, akn = ak @ a, akn @ an


def test_no_inverse_and_mismatched_parts_are_refused():
    with pytest.raises(ValueError, match="no inverse"):
        PHYS.block(STRUCTURE, PARAMS, inverse=True)
    short = dataclasses.replace(STRUCTURE, play_radii=(1e-3,))
    with pytest.raises(ValueError, match="play operators"):
        PHYS.simulate(short, PARAMS, np.zeros(2))


def test_sensor_block_runs_the_physics_in_metres_at_the_loop_rate():
    s_r = hc.virtual_sensor_block()
    u_mm = _position()[:2000]
    y_block, _ = s_r.simulate(u_mm * 1e-3, STRUCTURE.dt)
    assert_allclose(y_block, PHYS.simulate(STRUCTURE, PARAMS, u_mm)[0], rtol=0, atol=1e-12)
    # the loop's Ts: the compiled block and the readable step agree there too
    step, affine, body = s_r.pack(hc.TS)
    x = s_r.rest_state(0.0)
    xn = x.copy()
    x_ref = x.copy()
    for v in u_mm[:500] * 1e-3:
        out = affine[2] * step(body, x, xn, 0, affine[0] * v + affine[1]) + affine[3]
        ref, x_ref = s_r.step(x_ref, v, hc.TS)
        assert abs(out - ref) <= 1e-12
        x, xn = xn, x
    with pytest.raises(ValueError, match="no inverse"):
        hc.SensorBlock(STRUCTURE, PARAMS, True, model_family=PHYS)


def test_loop_training_fits_the_compensator_on_the_physics():
    models = hc.fit_sensor_models(sensor=hc.virtual_sensor_block(), training="loop")
    assert models.info["sensor_model"] == "virtual-physics"
    assert models.info["training_source"].startswith("<S_r on 3 mm")
    # a 1-cell mPL on the physics' 40 Hz sine response: a good, not an exact, fit
    assert 0.9 < models.model.info["r2"] < 1.0


def _control(capsys, tmp_path, scheme):
    out = tmp_path / scheme
    code = main(["control", "--scheme", scheme, "--experiment", "sine", "--sensor",
                 "virtual-physics", "--training", "recording", "--out", str(out)])
    printed = capsys.readouterr().out
    metrics = json.loads((out / "metrics.json").read_text())["cases"]["sine"]
    config = json.loads((out / "config.json").read_text())
    return code, printed, metrics, config


@pytest.mark.parametrize("scheme", ["direct", "weighting"])
def test_cli_runs_the_sine_on_the_physics_with_a_recording_trained_compensator(
        capsys, tmp_path, scheme):
    code, printed, m, config = _control(capsys, tmp_path, scheme)
    assert code == 0
    assert config["models"]["training_source"] == "<virtual sensor: sine, seed 2>"
    assert config["sensor_fit"]["model"] == "virtual-physics"
    assert m["bounded"]
    # the compensator never saw the physics: an error, of the document's order (eq. 7.6, 7.8)
    assert 1e-6 < m["e_p_max"] < 1e-3
    if scheme == "weighting":  # no neutral memory counted as a marginal pole
        assert "closed loop stable" in printed
