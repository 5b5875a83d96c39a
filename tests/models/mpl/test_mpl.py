"""mPL model (eq. 5.1-5.6, 5.13-5.14, 5.28-5.29): kernels vs reference, state, stability."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from hystkit.errors import FitDivergedError
from hystkit.models import mpl
from hystkit.models.mpl import kernels

DT = 0.025


def _input(n: int = 4000, seed: int = 0) -> np.ndarray:
    t = np.arange(n) * DT
    noise = np.random.default_rng(seed).standard_normal(n)
    return np.sin(np.pi * t) * np.exp(-t / 80) + 0.3 * np.sin(2.3 * t) + 0.05 * noise


STRUCT2 = mpl.MplStructure(n_cells=2, dt=DT)
PARAMS2 = mpl.MplParams(i_s=[0.1, 0.02], v_t=[0.2, 0.5], w=[1.0, 0.4, -0.3], v_b=-0.6)


def test_single_cell_linear_region_closed_form():
    # With a huge V_T the resistor is linear, f(v) = G v with G = 2 I_S / V_T, and the Euler
    # recursion for a step input has the closed form u_n = 1 - (1 - G dt)^n.
    g, v_t = 2.0, 1e6
    s = mpl.MplStructure(n_cells=1, dt=DT)
    p = mpl.MplParams(i_s=[g * v_t / 2], v_t=[v_t], w=[0.0, 1.0], v_b=0.0)
    y, _ = mpl.simulate(s, p, np.ones(200), x0=0.0)
    n = np.arange(200)
    assert_allclose(y, 1 - (1 - g * DT) ** n, rtol=1e-9, atol=1e-12)  # sinh(v/V_T) ~ v/V_T


def test_output_equation_eq_5_2():
    u = _input(50)
    x0 = np.array([0.3, -0.2])
    y, _ = mpl.simulate(STRUCT2, PARAMS2, u, x0=x0)
    assert y[0] == pytest.approx(1.0 * u[0] + 0.4 * 0.3 - 0.3 * -0.2 + 0.6, abs=1e-15)


def test_resistor_is_sinh_inside_the_knee_and_linear_outside():
    s = mpl.MplStructure(n_cells=1, dt=DT)
    p = mpl.MplParams(i_s=[0.1], v_t=[0.2], w=[1.0, 0.4])
    knee = mpl.knee_voltage(s, p)[0]
    # the slope at the knee equals the cap: (2 I_S / V_T) cosh(knee / V_T) = 1 / dt
    assert 2 * 0.1 / 0.2 * np.cosh(knee / 0.2) == pytest.approx(1 / DT, rel=1e-12)
    v = np.array([[-2 * knee], [-knee / 2], [0.0], [knee / 3], [3 * knee]])
    f = mpl.resistor_current(s, p, v)[:, 0]
    assert_allclose(f[1:4], 0.2 * np.sinh(v[1:4, 0] / 0.2), rtol=1e-14)
    f_knee = 0.2 * np.sinh(knee / 0.2)
    assert_allclose(f[4], f_knee + (3 * knee - knee) / DT, rtol=1e-14)
    assert_allclose(f[0], -f_knee - knee / DT, rtol=1e-14)  # odd: the corrected eq. 5.29


def test_cell_that_is_too_fast_everywhere_becomes_linear_at_the_cap():
    s = mpl.MplStructure(n_cells=1, dt=DT)
    p = mpl.MplParams(i_s=[100.0], v_t=[0.1], w=[0.0, 1.0])  # G = 2000 /s > 1/dt = 40 /s
    assert mpl.knee_voltage(s, p)[0] == 0.0
    # slope cap 1: the cell reaches any input in exactly one step (deadbeat, no overshoot)
    y, _x_end = mpl.simulate(s, p, np.array([0.7, 0.7, 0.7]), x0=0.0)
    assert_allclose(y, [0.0, 0.7, 0.7], atol=1e-15)


@settings(max_examples=200, deadline=None)
@given(log_i_s=st.lists(st.floats(-12, 6), min_size=1, max_size=4),
       log_v_t=st.floats(-7, 5), weights=st.lists(st.floats(-100, 100), min_size=5, max_size=5),
       cap=st.floats(0.05, 1.0), seed=st.integers(0, 1000))
def test_stability_limit_bounds_any_parameter_set(log_i_s, log_v_t, weights, cap, seed):
    """With the limit (slope cap <= 1), every cell voltage stays inside the hull of the input and
    the initial state, for any parameters: the model cannot blow up (sec. 5.3.5)."""
    n = len(log_i_s)
    s = mpl.MplStructure(n_cells=n, dt=DT, slope_cap=cap)
    p = mpl.MplParams(i_s=np.exp(log_i_s), v_t=np.full(n, np.exp(log_v_t)), w=weights[: n + 1],
                      v_b=weights[-1])
    rng = np.random.default_rng(seed)
    u = 3 * rng.standard_normal(500)
    x0 = rng.uniform(-5, 5, n)
    y, x_end = mpl.simulate(s, p, u, x0=x0)
    lo, hi = min(u.min(), x0.min()), max(u.max(), x0.max())
    assert np.all(np.isfinite(y))
    assert np.all((x_end >= lo - 1e-9) & (x_end <= hi + 1e-9))
    bound = abs(p.w[0]) * np.abs(u).max() + np.abs(p.w[1:]).sum() * max(abs(lo), abs(hi))
    assert np.all(np.abs(y + p.v_b) <= bound * (1 + 1e-12) + 1e-12)


def test_without_the_limit_euler_diverges():
    """The counter-example the limit exists for: the unlimited sinh cell blows up (sec. 5.3.5)."""
    i_s, v_t, u = 0.1, 0.05, 1.0
    x = 0.0
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(20):
            x = x + 2 * i_s * np.sinh((u - x) / v_t) * DT
    assert not np.isfinite(x) or abs(x) > 1e6
    s = mpl.MplStructure(n_cells=1, dt=DT)
    p = mpl.MplParams(i_s=[i_s], v_t=[v_t], w=[0.0, 1.0])
    _y, x_end = mpl.simulate(s, p, np.full(20, u), x0=0.0)
    assert 0.0 <= x_end[0] <= u


def test_inverse_undoes_forward_to_machine_precision():
    u = _input()
    y, _ = mpl.simulate(STRUCT2, PARAMS2, u)
    u_hat, _ = mpl.invert(STRUCT2, PARAMS2, y)
    assert_allclose(u_hat, u, rtol=0, atol=1e-12)  # eq. 5.13-5.14 with the order of fig. 5.12


def test_inverse_step_matches_kernel():
    u = _input(300)
    y, _ = mpl.simulate(STRUCT2, PARAMS2, u)
    u_hat, x_end = mpl.invert(STRUCT2, PARAMS2, y, x0=u[0])
    x = np.full(2, u[0])
    ref = []
    for y_n in y:
        e, x = mpl.invert_step(STRUCT2, PARAMS2, x, y_n)
        ref.append(e)
    assert_allclose(u_hat, ref, atol=1e-13)
    assert_allclose(x_end, x, atol=1e-13)


def test_unstable_inverse_is_reported_not_returned_as_nan():
    s = mpl.MplStructure(n_cells=1, dt=DT)
    # 1 + w_1 / w_0 = -4: the inverse cell is anti-stable (the forward model is non-minimum phase)
    p = mpl.MplParams(i_s=[0.5], v_t=[1.0], w=[0.2, -1.0])
    y, _ = mpl.simulate(s, p, _input(2000))
    with pytest.raises(FitDivergedError, match="diverged at sample"):
        mpl.invert(s, p, y)


def test_jacobian_matches_finite_differences_in_both_regions():
    u = 2.0 * _input(600)
    # the second cell is fast with a small V_T, so it spends time beyond its knee
    s = mpl.MplStructure(n_cells=2, dt=DT)
    p = mpl.MplParams(i_s=[0.05, 0.02], v_t=[0.3, 0.05], w=[0.8, 0.4, -0.3], v_b=0.1)
    knee = mpl.knee_voltage(s, p)
    x0 = np.full(2, u[0])
    _, jac = kernels.simulate_with_jacobian(u, x0, p.i_s, p.v_t, p.w, p.v_b, knee, 1 / DT, DT)
    x, beyond = x0, 0
    for u_n in u:
        beyond += abs(u_n - x[1]) > knee[1]
        _, x = mpl.step(s, p, x, u_n)
    assert beyond > 10  # the straight continuation of eq. 5.29 is exercised
    theta = p.to_vector()
    h = 1e-6

    def run(th):
        return mpl.simulate(s, mpl.MplParams.from_vector(th, 2), u, x0=x0)[0]

    fd = np.column_stack([(run(theta + h * e) - run(theta - h * e)) / (2 * h)
                          for e in np.eye(theta.size)])
    # central differences: truncation ~h^2, rounding ~eps/h ~ 1e-10 on O(1) outputs
    assert_allclose(jac, fd, rtol=0, atol=1e-7)
    assert_allclose(jac[:, 4], u)  # dy/dw0 = e


def test_params_vector_round_trip():
    theta = PARAMS2.to_vector()
    back = mpl.MplParams.from_vector(theta, 2)
    assert_allclose(back.to_vector(), theta, rtol=1e-15)
    assert_allclose(back.i_s, PARAMS2.i_s, rtol=1e-14)
    assert mpl.MplParams.from_dict(PARAMS2.to_dict()) == PARAMS2


@pytest.mark.parametrize("kwargs", [{"n_cells": 0}, {"dt": 0.0}, {"slope_cap": 2.0}])
def test_structure_rejects_bad_values(kwargs):
    with pytest.raises(ValueError):
        mpl.MplStructure(**kwargs)


def test_params_reject_non_positive_resistor_shape():
    with pytest.raises(ValueError, match=r"i_s must lie in \[1e-12, 1e\+12\]"):
        mpl.MplParams(i_s=[-1.0], v_t=[0.2], w=[1.0, 0.4])


def test_simulate_rejects_nan_input():
    u = _input(10)
    u[3] = np.nan
    with pytest.raises(ValueError, match="index 3"):
        mpl.simulate(STRUCT2, PARAMS2, u)
