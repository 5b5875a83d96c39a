"""Chua-Stromsmoe model (sec. 2.1.3, eq. 2.3-2.4): kernels, closed forms, local memory, fit."""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from hystkit.compensation import evaluate, fit_compensator
from hystkit.errors import FitDivergedError
from hystkit.models import chua, get_family, numerical_linearisation
from hystkit.models.chua import fit_chua
from hystkit.sensors import simulate_experiment

DT = 0.025
STRUCT2 = chua.ChuaStructure(n_elements=2, dt=DT)
PARAMS2 = chua.ChuaParams(k0=[1.0, 2.0], k_inf=[3.0, 0.5], y_s=[0.3, 0.5], g=[5.0, 0.5],
                          v_g=[0.2, 1.0], delta=[0.0, 0.1])


def _input(n: int = 4000, seed: int = 0) -> np.ndarray:
    t = np.arange(n) * DT
    noise = np.random.default_rng(seed).standard_normal(n)
    return np.sin(np.pi * t) * np.exp(-t / 80) + 0.3 * np.sin(2.3 * t) + 0.05 * noise


def _linear(k: float, g: float, delta: float = 0.0) -> chua.ChuaParams:
    # k0 = k_inf: f(y) = k y; a huge V_g makes sinh linear to ~1e-12 over |v| <= 1
    return chua.ChuaParams(k0=[k], k_inf=[k], y_s=[1.0], g=[g], v_g=[1e6], delta=[delta])


def test_linear_element_step_response_closed_form():
    # f(y) = k y, g(v) = G v: y_n = (1 - (1 - G k dt)^(n+1)) / k (output after the step)
    k, g = 2.0, 4.0
    s = chua.ChuaStructure(dt=DT)
    y, _ = chua.simulate(s, _linear(k, g), np.ones(100), x0=0.0)
    n = np.arange(100)
    assert_allclose(y, (1 - (1 - g * k * DT) ** (n + 1)) / k, rtol=1e-9)  # sinh ~ linear


def test_fast_element_with_dead_band_is_the_play_operator():
    # G beyond the Euler cap: beyond the band g is the capped line of slope 1 / dt, so one step
    # lands on the band edge: y = max(u - delta, min(u + delta, y_prev)) (eq. 2.11), exactly.
    delta = 0.2
    u = _input(800)
    y, _ = chua.simulate(chua.ChuaStructure(dt=DT), _linear(1.0, 1e4, delta), u, x0=0.0)
    play, prev = np.empty_like(u), 0.0
    for n, u_n in enumerate(u):
        prev = max(u_n - delta, min(u_n + delta, prev))
        play[n] = prev
    assert_allclose(y, play, rtol=0, atol=1e-12)


def test_eq_2_4_input_is_restoring_plus_inverse_dissipation():
    # u = f(y) + g^-1(dy/dt) (eq. 2.4) holds for every Euler step, inside the knee
    s = chua.ChuaStructure(dt=DT)
    p = chua.ChuaParams(k0=[1.5], k_inf=[0.7], y_s=[0.4], g=[2.0], v_g=[0.3], delta=[0.0])
    u = _input(2000)
    x0 = chua.restoring_inverse(p, u[0])
    y, _ = chua.simulate(s, p, u, x0=x0)
    prev = np.concatenate([x0, y[:-1]])
    rate = (y - prev) / DT
    rebuilt = chua.restoring(p, prev[:, None])[:, 0] + 0.3 * np.arcsinh(rate / (2.0 * 0.3))
    assert_allclose(rebuilt, u, rtol=0, atol=1e-12)


def _loop_area(y: np.ndarray, u: np.ndarray) -> float:
    """Area of the closed loop (y, u) over one period (cyclic trapezoid rule)."""
    return abs(float(np.sum(0.5 * (np.roll(y, -1) + y) * (np.roll(u, -1) - u))))


def test_loop_widens_with_frequency_and_vanishes_at_dc_without_dead_band():
    """The document: loops grow with frequency; without a dead band there is no DC loop."""
    s = chua.ChuaStructure(dt=DT)
    k, g = 1.0, 2.0  # time constant 1 / (G k) = 0.5 s
    areas = []
    for period in (40000, 4000, 400, 80):
        u = np.sin(2 * np.pi * np.arange(6 * period) / period)
        y, _ = chua.simulate(s, _linear(k, g), u)
        areas.append(_loop_area(y[-period:], u[-period:]))  # 5 periods: transient < 1e-8
        # closed form: y_n = (1 - a) y_n-1 + G dt u_n with a = G k dt, a linear filter H; the
        # cyclic trapezoid area of a sampled ellipse is pi |H| sin(-arg H) sin(w) / w
        w = 2 * np.pi / period
        h = g * DT / (1 - (1 - g * k * DT) * np.exp(-1j * w))
        assert areas[-1] == pytest.approx(np.pi * abs(h) * np.sin(-np.angle(h)) * np.sin(w) / w,
                                          rel=1e-6)
    assert np.all(np.diff(areas) > 0)
    assert areas[0] < 0.01  # ~ pi w tau: vanishes at DC


def test_dead_band_keeps_a_loop_at_dc():
    s = chua.ChuaStructure(dt=DT)
    u = np.sin(2 * np.pi * np.arange(80000) / 40000)
    y, _ = chua.simulate(s, _linear(1.0, 20.0, delta=0.1), u)
    # the slow limit is the play of radius 0.1, whose loop is a parallelogram of area
    # 4 delta (amplitude - delta) = 0.36; the lag outside the band adds about pi w tau = 1e-3
    assert _loop_area(y[40000:], u[40000:]) == pytest.approx(4 * 0.1 * 0.9, rel=0.01)


def test_half_wave_symmetry_of_odd_models():
    # property 9 of Chua-Stromsmoe (sec. 2.1.3): odd f and g, u(t + T/2) = -u(t) => the
    # periodic output has the same symmetry
    t = np.arange(40 * 80)
    u = 0.9 * np.sin(2 * np.pi * t / 80)
    y, _ = chua.simulate(STRUCT2, PARAMS2, u)
    last = y[-80:]
    assert_allclose(last[40:], -last[:40], rtol=0, atol=1e-9)  # transient decayed over 39 T


@settings(max_examples=60, deadline=None)
@given(logs=st.lists(st.floats(-4, 4), min_size=5, max_size=5), delta=st.floats(0, 1),
       cap=st.floats(0.05, 1.0), seed=st.integers(0, 1000))
def test_stability_limit_bounds_any_parameter_set(logs, delta, cap, seed):
    """With the slope cap <= 1 no step overshoots: y stays between f^-1(min u - delta),
    f^-1(max u + delta) and its start, for any parameters."""
    s = chua.ChuaStructure(dt=DT, slope_cap=cap)
    p = chua.ChuaParams(*np.exp(np.array(logs))[:, None], delta=[delta])
    rng = np.random.default_rng(seed)
    u = 3 * rng.standard_normal(300)
    x0 = rng.uniform(-5, 5, 1)
    y, _ = chua.simulate(s, p, u, x0=x0)
    lo = min(x0[0], chua.restoring_inverse(p, u.min() - delta)[0])
    hi = max(x0[0], chua.restoring_inverse(p, u.max() + delta)[0])
    span = 1e-9 * (1 + hi - lo)
    assert np.all((y >= lo - span) & (y <= hi + span))


def test_inverse_undoes_forward_to_machine_precision():
    u = _input()
    y, _ = chua.simulate(STRUCT2, PARAMS2, u)
    u_hat, _ = chua.invert(STRUCT2, PARAMS2, y)
    # element 1 has no dead band, so every step moves and fixes u; bisection to 1e-14
    assert_allclose(u_hat, u, rtol=0, atol=1e-11)


def test_inverse_kernel_matches_readable_step():
    u = _input(300)
    y, _ = chua.simulate(STRUCT2, PARAMS2, u)
    x0 = chua.restoring_inverse(PARAMS2, u[0])
    u_hat, x_end = chua.invert(STRUCT2, PARAMS2, y, x0=x0)
    x, ref = x0, []
    for y_n in y:
        e, x = chua.invert_step(STRUCT2, PARAMS2, x, y_n)
        ref.append(e)
    assert_allclose(u_hat, ref, rtol=0, atol=1e-12)  # bisection tolerance 1e-14 (1 + |u|)
    assert_allclose(x_end, x, rtol=0, atol=1e-12)


def test_inverse_inside_the_dead_band_returns_its_middle():
    p = _linear(2.0, 1.0, delta=0.3)
    s = chua.ChuaStructure(dt=DT)
    u_hat, _ = chua.invert(s, p, np.full(5, 0.25), x0=0.25)
    assert_allclose(u_hat, 2.0 * 0.25, rtol=1e-13)  # f(y): the middle of [f(y) -+ delta]


@pytest.mark.parametrize("ulps", [-3, -1, 1, 3])
def test_an_output_constant_to_rounding_stays_in_the_middle_of_the_dead_band(ulps):
    # y off the state by a few ulps: before, the inverse jumped to f(y) +- delta by the sign of
    # that rounding (fuzz seeds 1782420 and 62625); now it is constant, readable and compiled
    p = _linear(2.0, 1.0, delta=0.3)
    s = chua.ChuaStructure(dt=DT)
    y = np.full(6, 0.25)
    y[1:] += ulps * np.spacing(0.25)
    u_hat, x_end = chua.invert(s, p, y, x0=0.25)
    assert_allclose(u_hat, 2.0 * 0.25, rtol=1e-13)
    assert x_end[0] == 0.25  # no element moved
    u_step, x_step = chua.invert_step(s, p, np.array([0.25]), float(y[1]))
    assert u_step == pytest.approx(2.0 * 0.25, rel=1e-13) and x_step[0] == 0.25
    y_back, _ = chua.simulate(s, p, u_hat)  # from rest at u_hat[0] = f(0.25): x = 0.25
    assert_allclose(y_back, y, rtol=0, atol=1e-14)


def test_recovers_known_parameters_from_noise_free_data():
    truth = chua.ChuaParams(k0=[1.2], k_inf=[0.6], y_s=[0.4], g=[3.0], v_g=[0.5], delta=[0.1])
    s = chua.ChuaStructure(dt=DT)
    t = np.arange(8000) * DT
    u = np.sin(np.pi * t) * np.exp(-t / 100) + 0.2 * np.sin(2.3 * t)
    y, _ = chua.simulate(s, truth, u)
    result = fit_chua(u, y, s)
    assert result.converged
    assert result.cost < 1e-20
    # noise-free data: the optimum is the truth (finite-difference Jacobian: ~1e-8 relative)
    assert_allclose(result.params.to_vector(), truth.to_vector(), rtol=1e-6, atol=1e-8)


def test_acceptance_test_rejections_are_reported():
    u = _input(1000)
    with pytest.raises(FitDivergedError, match="rejected .no thanks."):
        fit_chua(u, 0.5 * u, chua.ChuaStructure(dt=DT), starts=[_linear(2.0, 1.0)],
                 max_nfev=3, screen_nfev=2, accept=lambda p: False, accept_reason="no thanks")


def test_params_round_trips():
    assert chua.ChuaParams.from_dict(PARAMS2.to_dict()) == PARAMS2
    back = chua.ChuaParams.from_vector(PARAMS2.to_vector(), 2)
    assert_allclose(back.to_vector(), PARAMS2.to_vector(), rtol=1e-15)
    family = get_family("chua")
    assert family.make_structure(DT, 2) == STRUCT2


@pytest.mark.parametrize("kwargs", [{"n_elements": 0}, {"dt": -1.0}, {"slope_cap": 2.0}])
def test_structure_rejects_bad_values(kwargs):
    with pytest.raises(ValueError):
        chua.ChuaStructure(**kwargs)


@pytest.mark.parametrize("field, value", [("k0", [-1.0]), ("v_g", [0.0]), ("delta", [-0.1]),
                                          ("g", [np.nan])])
def test_params_reject_bad_values(field, value):
    d = _linear(1.0, 1.0).to_dict() | {field: value}
    with pytest.raises(ValueError):
        chua.ChuaParams.from_dict(d)


def test_simulate_rejects_nan_input():
    u = _input(10)
    u[3] = np.nan
    with pytest.raises(ValueError, match="index 3"):
        chua.simulate(STRUCT2, PARAMS2, u)


@pytest.mark.parametrize("mode", ["direct", "inverse"])
def test_compensator_on_the_virtual_sensor(mode):
    comp = fit_compensator(simulate_experiment("sine", 1), model="chua", mode=mode)
    scores = evaluate(comp, simulate_experiment("sine", 2))
    assert np.isfinite(scores["r2"])
    if mode == "inverse":
        assert scores["r2"] > scores["linear_r2"]
    # direct (sensor -> position) is not asserted to beat the line: an element whose f and g
    # increase only lags its input, the opposite loop orientation (docs/models/circuits.md)


# --- the family protocol: loop blocks, rest states, at(dt), records, linearisation ---------

FAMILY = get_family("chua")


@pytest.mark.parametrize("inverse", [False, True])
def test_block_equals_step_from_a_non_rest_state(inverse, drive):
    rng = np.random.default_rng(3)
    x0 = np.array([0.8, -0.6])
    if inverse:
        signal = np.sum(x0) + np.cumsum(0.05 * rng.standard_normal(300))
        run = FAMILY.invert_step
    else:
        signal = 2.0 * rng.standard_normal(300)  # large drives reach the capped line of g
        run = FAMILY.step
    blk = FAMILY.block(STRUCT2, PARAMS2, inverse)
    assert blk.n_state == 2
    out_blk, x_blk = drive(blk, x0, signal, off=3)
    out_ref, x_ref = drive(lambda x, v: run(STRUCT2, PARAMS2, x, v), x0, signal)
    assert np.all(np.isfinite(out_ref))
    assert_allclose(out_blk, out_ref, rtol=0, atol=1e-12)
    assert_allclose(x_blk, x_ref, rtol=0, atol=1e-12)
    if not inverse:
        _, knee = chua.limits(STRUCT2, PARAMS2)
        v = signal[:, None] - chua.restoring(PARAMS2, np.vstack([x0, x_ref[:-1]]))
        assert np.sum(np.abs(v) > knee) > 50  # the Euler limit is exercised


@pytest.mark.parametrize("value", [-0.7, 0.0, 0.45])
def test_rest_state_is_the_start_of_runs_and_a_fixed_point(value):
    x_fwd = FAMILY.rest_state(STRUCT2, PARAMS2, value)
    y, x_next = FAMILY.step(STRUCT2, PARAMS2, x_fwd, value)
    assert_allclose(x_next, x_fwd, rtol=0, atol=1e-12)
    y_run, _ = FAMILY.simulate(STRUCT2, PARAMS2, np.full(5, value))
    assert_allclose(y_run, y, rtol=0, atol=1e-12)
    x_inv = FAMILY.rest_state(STRUCT2, PARAMS2, value, inverse=True)
    u_hat, x_next = FAMILY.invert_step(STRUCT2, PARAMS2, x_inv, value)
    assert_allclose(x_next, x_inv, rtol=0, atol=1e-12)
    assert np.sum(x_inv) == pytest.approx(value, abs=1e-12)
    u_run, _ = FAMILY.invert(STRUCT2, PARAMS2, np.full(5, value))
    assert_allclose(u_run, u_hat, rtol=0, atol=1e-12)


def test_at_finer_dt_keeps_the_limited_dissipation_function():
    v = np.linspace(-3, 3, 601)[:, None]
    for factor in (0.5, 0.25, 0.1):
        fine = FAMILY.at(STRUCT2, DT * factor)
        assert fine.dt == DT * factor and fine.n_elements == 2
        assert_allclose(chua.limits(fine, PARAMS2)[0], chua.limits(STRUCT2, PARAMS2)[0],
                        rtol=1e-12)
        assert_allclose(chua.dissipation(fine, PARAMS2, v), chua.dissipation(STRUCT2, PARAMS2, v),
                        rtol=1e-12, atol=1e-12)
        assert FAMILY.at(fine, DT) == STRUCT2  # and back
    assert FAMILY.at(STRUCT2, DT) == STRUCT2


def test_at_coarser_dt_saturates_the_cap_and_stays_monotone():
    half = chua.ChuaStructure(n_elements=2, dt=DT, slope_cap=0.5)
    assert FAMILY.at(half, 2 * DT).slope_cap == pytest.approx(1.0)  # same ODE, cap 1
    coarse = FAMILY.at(STRUCT2, 4 * DT)
    assert coarse.slope_cap == 1.0 and coarse.dt == 4 * DT
    # monotone Euler step: a step input never overshoots the element's rest value
    y, x = FAMILY.simulate(coarse, PARAMS2, np.ones(200), x0=[0.0, 0.0])
    rest = chua.restoring_inverse(PARAMS2, 1.0)
    assert np.all(x <= rest + 1e-12) and np.all(np.diff(y) >= -1e-12)


def test_at_finer_dt_converges_to_the_same_ode():
    u = _input(400)
    t = np.arange(u.size) * DT
    errors = []
    for k in (2, 4, 8):
        t_k = np.arange(u.size * k) * DT / k
        y_k, _ = FAMILY.simulate(FAMILY.at(STRUCT2, DT / k), PARAMS2, np.interp(t_k, t, u))
        errors.append(y_k)
    ref, _ = FAMILY.simulate(FAMILY.at(STRUCT2, DT / 32), PARAMS2,
                             np.interp(np.arange(u.size * 32) * DT / 32, t, u))
    gaps = [np.max(np.abs(y[k - 1::k] - ref[32 - 1::32])) for k, y in zip((2, 4, 8), errors)]
    assert gaps[0] > gaps[1] > gaps[2]  # forward Euler: first order in the step
    assert gaps[2] < 0.6 * gaps[1] < 0.36 * gaps[0]


def test_records_round_trip_and_old_model_files_load():
    d = PARAMS2.to_dict()
    assert chua.ChuaParams.from_dict(json.loads(json.dumps(d))) == PARAMS2
    assert chua.ChuaStructure.from_dict(STRUCT2.to_dict()) == STRUCT2
    old = {"k0": [1.0, 2.0], "k_inf": [3.0, 0.5], "y_s": [0.3, 0.5], "g": [5.0, 0.5],
           "v_g": [0.2, 1.0], "delta": [0.0, 0.1]}  # as written by hystkit before the move
    assert d == old and chua.ChuaParams.from_dict(old) == PARAMS2
    old_structure = {"n_elements": 2, "dt": DT, "slope_cap": 1.0}  # asdict(structure)
    assert STRUCT2.to_dict() == old_structure
    assert chua.ChuaStructure(**old_structure) == STRUCT2
    assert PARAMS2 != chua.ChuaParams.from_dict({**old, "delta": [0.0, 0.2]})


@pytest.mark.parametrize("inverse", [False, True])
def test_analytical_linearisation_matches_numerical(inverse):
    x = np.array([0.3, -0.2])
    run = FAMILY.invert_step if inverse else FAMILY.step
    for u in (0.9, -1.4, 2.5):  # inside the sinh, and beyond a knee
        if inverse:
            u = float(np.sum(x)) + 0.02 * u
        exact = FAMILY.linearise(STRUCT2, PARAMS2, x, u, inverse)
        approx = numerical_linearisation(lambda xx, uu: run(STRUCT2, PARAMS2, xx, uu), x, u)
        for e, a in zip(exact, approx):
            assert_allclose(e, a, rtol=1e-5, atol=1e-7)
