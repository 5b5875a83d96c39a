"""Closed loop of ch. 7: blocks, kernel vs reference, explicit state, linear limit, instability."""

from __future__ import annotations

import json

import control as ct
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from hystkit import control as hc
from hystkit.errors import InputError
from hystkit.sensors import simulate_experiment

TS = hc.TS
GAIN = 40.0  # sensor units per metre of the ideal linear sensor (any non-zero value will do)
IDEAL = hc.linear_block(GAIN, name="ideal sensor")
EXACT = hc.linear_block(1 / GAIN, name="exact compensator")


@pytest.fixture(scope="module")
def models() -> hc.SensorModels:
    return hc.fit_sensor_models()  # about 2 s: S_r on noise, compensator and S_m on sine


def _ideal_loop(scheme: str, pid: hc.PID, **kw) -> hc.ControlLoop:
    return hc.ControlLoop(scheme, IDEAL, pid, compensator=EXACT,
                          model=hc.linear_block(GAIN, name="ideal model"), sensor_gain=1 / GAIN,
                          **kw)


def _reference(n: int) -> np.ndarray:
    """The eq. 7.3 sine plus a cubic move: smooth and non-periodic."""
    t = np.arange(n) * TS
    return hc.sine_reference(n) + 1e-3 * np.clip(t - 1, 0, 1) ** 2 * (3 - 2 * np.clip(t - 1, 0, 1))


# --------------------------------------------------------------------------- blocks


def test_plant_is_the_exact_zoh_discretisation():
    a, b, c = hc.plant_matrices(hc.MASS, TS)
    ref = ct.c2d(ct.ss([[0, 1], [0, 0]], [[0], [1 / hc.MASS]], [[1, 0]], 0), TS, "zoh")
    # the double integrator's matrix exponential is a finite series: agreement to round-off
    assert_allclose(a, ref.A, rtol=1e-13, atol=1e-18)
    assert_allclose(b, ref.B.ravel(), rtol=1e-12)
    assert_allclose(c, ref.C.ravel())


@pytest.mark.parametrize("tf", [0.0, 3e-3])
def test_pid_transfer_function_is_eq_7_2(tf):
    pid = hc.PID(kp=545.0, ti=0.029, td=0.0573, tf=tf)
    num, den = pid.transfer_coefficients(TS)
    z = np.exp(1j * np.linspace(0.01, 3.0, 40))
    derivative = 0.0573 * (z - 1) / ((tf + TS) * z - tf)  # = Td (z - 1) / (Ts z) for Tf = 0
    expected = 545.0 * (1 + TS / (0.029 * (z - 1)) + derivative)
    # the expanded polynomials lose a few digits to cancellation near z = 1
    assert_allclose(np.polyval(num, z) / np.polyval(den, z), expected, rtol=1e-10)


def test_blocks_refuse_bad_parameters():
    with pytest.raises(ValueError, match="mass"):
        hc.Plant(mass=-1.0)
    with pytest.raises(ValueError, match="ti"):
        hc.PID(kp=1.0, ti=0.0)
    with pytest.raises(ValueError, match="f_q"):
        hc.DisturbanceObserver(f_q=0.0)
    with pytest.raises(ValueError, match="compensator"):
        hc.ControlLoop("direct", IDEAL, hc.DOCUMENT_PID_DIRECT)
    with pytest.raises(ValueError, match="S_m"):
        hc.ControlLoop("weighting", IDEAL, hc.DOCUMENT_PID_WEIGHTING)
    with pytest.raises(ValueError, match="identity"):
        hc.ControlLoop("weighting", IDEAL, hc.DOCUMENT_PID_WEIGHTING, model=IDEAL)
    with pytest.raises(ValueError, match="observer"):
        hc.ControlLoop("weighting", IDEAL, hc.DOCUMENT_PID_WEIGHTING, model=EXACT,
                       dob=hc.DisturbanceObserver(10.0))


def test_observer_poles_sit_where_the_q_filter_puts_them():
    dob = hc.DisturbanceObserver(f_q=40.0)
    gain = dob.observer_gain(hc.MASS, TS)
    from hystkit.control._blocks import extended_matrices

    a, c = extended_matrices(hc.MASS, TS)
    poles = np.linalg.eigvals(a - np.outer(gain, c))
    # triple pole: eigenvalues of a defective matrix carry ~eps^(1/3) error
    assert_allclose(poles, np.exp(-2 * np.pi * 40.0 * TS), atol=1e-4)


# --------------------------------------------------------------------------- linear limit


@pytest.mark.parametrize("scheme", hc.SCHEMES)
@pytest.mark.parametrize("pid", [hc.DOCUMENT_PID_DIRECT, hc.PID(120.0, 0.25, 0.06, tf=2e-3)],
                         ids=["document", "filtered"])
def test_ideal_sensor_and_exact_compensator_reduce_to_the_linear_loop(scheme, pid):
    r = _reference(round(3.0 / TS))
    res = hc.simulate_loop(_ideal_loop(scheme, pid), r)
    num, den = pid.transfer_coefficients(TS)
    a, b, c = hc.plant_matrices(hc.MASS, TS)
    loop = ct.ss(a, b.reshape(2, 1), c.reshape(1, 2), 0, TS) * ct.tf2ss(ct.tf(num, den, TS))
    y_ref = ct.forced_response(ct.feedback(loop, 1), np.arange(r.size) * TS, r).outputs
    assert res.bounded
    # 1e-9 of the 3 mm amplitude: two different evaluation orders of the same linear recursion
    assert_allclose(res.y, y_ref, rtol=0, atol=1e-9 * np.max(np.abs(r)))


def test_dob_with_exact_model_and_no_disturbance_changes_nothing():
    r = _reference(4000)
    plain = hc.simulate_loop(_ideal_loop("direct", hc.DOCUMENT_PID_DIRECT), r)
    with_dob = hc.simulate_loop(_ideal_loop("direct", hc.DOCUMENT_PID_DIRECT,
                                            dob=hc.DisturbanceObserver(30.0)), r)
    # the observer starts on the true state and its model is exact: no innovation ever
    assert_allclose(with_dob.d_hat, 0.0, atol=1e-9)
    assert_allclose(with_dob.y, plain.y, rtol=0, atol=1e-13)


def test_dob_rejects_an_input_force_step():
    n = round(2.0 / TS)
    r = np.zeros(n)
    d_in = np.where(np.arange(n) * TS >= 0.5, 1.0, 0.0)  # 1 N from 0.5 s
    pid = hc.PID(kp=545.0, ti=np.inf, td=0.0573)  # no integral: only the DOB can remove it
    plain = hc.simulate_loop(_ideal_loop("direct", pid), r, d_in=d_in)
    dob = hc.simulate_loop(_ideal_loop("direct", pid, dob=hc.DisturbanceObserver(30.0)), r,
                           d_in=d_in)
    # without integral action a PD settles where its force cancels it, y = d / Kp; the Q_31
    # DOB removes a constant force
    assert_allclose(plain.y[-1], 1.0 / 545.0, rtol=1e-3)
    assert abs(dob.y[-1]) < 1e-6 * abs(plain.y[-1])
    assert_allclose(dob.d_hat[-1], 1.0, rtol=1e-6)


# --------------------------------------------------------------------------- kernel vs reference


CONFIGS = {
    "direct": {"scheme": "direct"},
    "weighting": {"scheme": "weighting"},
    "direct+dob+filter": {"scheme": "direct", "dob": hc.DisturbanceObserver(25.0), "tf": 1e-3},
    "weighting+dob": {"scheme": "weighting", "dob": hc.DisturbanceObserver(25.0)},
    "saturated+anti-windup": {"scheme": "direct", "u_max": 2.0, "anti_windup": True},
}


def _fitted_loop(models, scheme, dob=None, tf=0.0, u_max=np.inf, anti_windup=False):
    pid = hc.DOCUMENT_PID_DIRECT if scheme == "direct" else hc.DOCUMENT_PID_WEIGHTING
    pid = hc.PID(pid.kp, pid.ti, pid.td, tf=tf, anti_windup=anti_windup)
    return hc.build_loop(scheme, models, pid=pid, plant=hc.Plant(u_max=u_max), dob=dob)


@pytest.mark.parametrize("name", CONFIGS)
def test_kernel_matches_the_plain_python_reference(models, name):
    loop = _fitted_loop(models, **CONFIGS[name])
    n = 1500
    rng = np.random.default_rng(3)
    r = _reference(n) * 1.5
    extra = {"d_out": np.where(np.arange(n) > 700, 1e-3, 0.0),
             "d_in": 0.05 * rng.standard_normal(n), "noise": 1e-4 * rng.standard_normal(n)}
    fast = hc.simulate_loop(loop, r, **extra)
    slow = hc.simulate_loop_reference(loop, r, **extra)
    assert fast.bounded and slow.bounded
    # same operations in the same order; only libm's sinh may differ in the last bit
    for key, scale in (("y", 1e-3), ("s", 0.1), ("y_hat", 1e-3), ("e", 1e-3), ("u", 10.0)):
        assert_allclose(getattr(fast, key), getattr(slow, key), rtol=0, atol=1e-11 * scale)
    assert_allclose(fast.state.to_vector(), slow.state.to_vector(), rtol=1e-10, atol=1e-14)
    if name.startswith("saturated"):
        assert np.max(np.abs(fast.u)) == 2.0  # the limit was active


@pytest.mark.parametrize("name", ["direct", "weighting+dob"])
def test_split_run_equals_whole_run(models, name):
    loop = _fitted_loop(models, **CONFIGS[name])
    r = _reference(3000)
    d_out = np.where(np.arange(3000) > 1500, 1e-3, 0.0)
    whole = hc.simulate_loop(loop, r, d_out=d_out)
    first = hc.simulate_loop(loop, r[:1234], d_out=d_out[:1234])
    second = hc.simulate_loop(loop, r[1234:], d_out=d_out[1234:], state=first.state,
                              t0=1234 * TS)
    # bit-identical: the state carries all the memory of every block
    for key in ("y", "s", "y_hat", "s_hat", "e", "u", "d_hat", "y_hat_plant"):
        if getattr(whole, key) is not None:
            assert_array_equal(np.concatenate([getattr(first, key), getattr(second, key)]),
                               getattr(whole, key))
    assert_array_equal(second.state.to_vector(), whole.state.to_vector())
    assert_allclose(second.t, whole.t[1234:], rtol=1e-12)


@settings(max_examples=15, deadline=None)
@given(split=st.integers(1, 799), scheme=st.sampled_from(hc.SCHEMES))
def test_split_anywhere_equals_whole(split, scheme):
    loop = _ideal_loop(scheme, hc.DOCUMENT_PID_DIRECT)
    r = _reference(800)
    whole = hc.simulate_loop(loop, r)
    first = hc.simulate_loop(loop, r[:split])
    second = hc.simulate_loop(loop, r[split:], state=first.state)
    assert_array_equal(np.concatenate([first.y, second.y]), whole.y)


def test_loop_state_round_trip(models):
    loop = _fitted_loop(models, "weighting", dob=hc.DisturbanceObserver(20.0))
    state = hc.simulate_loop(loop, _reference(500)).state
    again = hc.LoopState.from_vector(loop, state.to_vector())
    assert_array_equal(again.to_vector(), state.to_vector())
    assert (again.sensor.size, again.compensator.size, again.model.size) == loop.sizes()


# --------------------------------------------------------------------------- rest, tare, fits


@pytest.mark.parametrize("scheme", hc.SCHEMES)
def test_zeroed_loop_at_rest_stays_at_rest(models, scheme):
    loop = hc.build_loop(scheme, models)  # zeroed on the sensor's rest reading
    res = hc.simulate_loop(loop, np.zeros(2000))
    # round-off only: the rest state is (u - offset) / scale, the kernel's u * a + b
    assert_allclose(res.y, 0.0, atol=1e-15)  # metres
    assert_allclose(res.u, 0.0, atol=1e-9)  # newtons


def test_tare_zeroes_the_estimate_at_rest(models):
    raw = hc.build_loop("weighting", models, zero_at_start=False)
    zeroed = hc.tare(raw)
    s0, _ = raw.sensor.step(raw.sensor.rest_state(0.0), 0.0, TS)
    c, m = zeroed.compensator, zeroed.model
    assert abs(c.step(c.rest_state(s0), s0, TS)[0]) < 1e-15  # metres
    assert_allclose(m.step(m.rest_state(0.0), 0.0, TS)[0], s0, rtol=0, atol=1e-15)
    assert_array_equal(c.params.to_vector(), raw.compensator.params.to_vector())


def test_models_are_fitted_separately(models):
    assert models.sensor is not models.compensator and models.sensor is not models.model
    assert models.sensor.params != models.model.params
    assert models.sensor.info["r2"] > 0.99  # S_r describes the virtual sensor's noise run
    assert models.sensor_gain > 0


def test_loop_training_refuses_an_exact_copy_of_the_sensor():
    with pytest.raises(InputError, match="identity"):
        hc.fit_sensor_models(training="loop", model_cells=3)


def test_sensor_at_loop_rate_stays_close_to_its_fitting_rate(models):
    """Running the 40 Hz fit at Ts changes little (docs/control.md quotes the number)."""
    rec = simulate_experiment("noise", 1)
    p = rec.position * 1e-3
    s40, _ = models.sensor.simulate(p, rec.dt)
    t_fine = np.arange(0.0, rec.time[-1], TS)
    s_ts, _ = models.sensor.simulate(np.interp(t_fine, rec.time, p), TS)
    back = np.interp(rec.time, t_fine, s_ts)
    r2 = 1 - np.sum((back - s40) ** 2) / np.sum((s40 - s40.mean()) ** 2)
    assert r2 > 0.998


@pytest.mark.parametrize("which", ["sensor", "compensator", "inverse"])
def test_linearisation_matches_finite_differences(models, which):
    if which == "inverse":  # a forward model run as its analytical inverse
        base = models.sensor
        block = hc.SensorBlock(base.structure, base.params, True, base.out_offset,
                               base.out_scale, base.in_offset, base.in_scale)
    else:
        block = getattr(models, which)
    u0 = 0.02 if which == "compensator" else 1e-3
    x0 = block.rest_state(u0) + 0.05 * np.arange(block.n_state)
    a, b, c, d = block.linearise(x0, u0, TS)
    h_u = 1e-7 * block.in_scale
    y_p, x_p = block.step(x0, u0 + h_u, TS)
    y_m, x_m = block.step(x0, u0 - h_u, TS)
    # central differences: error O(h^2) relative to the slopes
    # central differences: O(h^2) truncation, round-off ~ eps |x| / h relative to max |b|
    assert_allclose((x_p - x_m) / (2 * h_u), b, rtol=1e-5, atol=1e-6 * np.max(np.abs(b)))
    assert_allclose((y_p - y_m) / (2 * h_u), d, rtol=1e-5)
    for k in range(block.n_state):
        dx = np.zeros(block.n_state)
        dx[k] = 1e-7
        y_p, x_p = block.step(x0 + dx, u0, TS)
        y_m, x_m = block.step(x0 - dx, u0, TS)
        assert_allclose((x_p - x_m) / 2e-7, a[:, k], rtol=1e-5, atol=1e-9)
        assert_allclose((y_p - y_m) / 2e-7, c[k], rtol=1e-5, atol=1e-12)


# --------------------------------------------------------------------------- instability


@pytest.mark.parametrize("pid", [hc.PID(kp=-545.0, ti=0.029, td=0.0573),
                                 hc.PID(kp=1e7, td=0.2)], ids=["positive feedback", "too fast"])
@pytest.mark.parametrize("scheme", hc.SCHEMES)
def test_unstable_loop_is_detected_and_cut_not_nan(models, scheme, pid):
    loop = hc.build_loop(scheme, models, pid=pid)
    r = hc.sine_reference(round(5.0 / TS))
    res = hc.simulate_loop(loop, r)
    assert not res.bounded
    assert 0 < res.stop_step < r.size
    assert_allclose(res.stop_time, res.stop_step * TS)
    assert res.state is None and "position" in res.stop_reason
    for key in ("t", "r", "y", "s", "y_hat", "s_hat", "e", "u", "y_hat_plant"):
        arr = getattr(res, key)
        assert arr.size == res.stop_step and np.all(np.isfinite(arr)), key
    assert np.all(np.abs(res.y) <= loop.y_limit)
    metrics = res.metrics()
    assert metrics["bounded"] is False and metrics["stop_step"] == res.stop_step
    json.dumps(metrics, allow_nan=False)  # JSON-safe: no NaN anywhere
    ref = hc.simulate_loop_reference(loop, r[: res.stop_step + 5])
    assert ref.stop_step == res.stop_step


def test_response_metrics_and_frame(models):
    res = hc.simulate_loop(hc.build_loop("direct", models), hc.sine_reference(2000))
    m = res.metrics()
    for key in ("e_p_max", "e_p_mean", "e_p_rms", "tracking_rms", "bounded", "seconds"):
        assert key in m
    assert_allclose(m["e_p_max"], np.max(np.abs(res.r - res.y)))
    frame = res.to_pandas()
    assert list(frame.columns) == ["r", "y", "s", "y_hat", "s_hat", "y_hat_plant", "e", "u"]
    assert frame.shape == (2000, 8)
