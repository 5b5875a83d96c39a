"""The document's own mPL fitting setups (issue 14.4): the unlimited sinh (sec. 5.3.3), a fit
from one exact start (table 5.2) and fmincon's constraint sum |w| <= B."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.errors import FitDivergedError
from hystkit.identification import NormalEquations
from hystkit.identification._constrained import minimise_with_weight_sum
from hystkit.models import FitStart, get_family
from hystkit.models.mpl import fit as mpl_fit
from hystkit.models.mpl import kernels
from hystkit.models.mpl import model as mpl

FAMILY = get_family("mpl")
DT = 0.025
TRUE = mpl.MplParams(i_s=[0.5], v_t=[0.3], w=[1.5, -0.8], v_b=0.1)


@pytest.fixture(scope="module")
def data() -> tuple[np.ndarray, np.ndarray]:
    """A decaying 0.2 Hz sine through a known 1-cell mPL, with 1 % noise (seeded)."""
    t = np.arange(4000) * DT
    u = np.sin(2 * np.pi * 0.2 * t) * np.exp(-t / 100)
    y, _ = mpl.simulate(mpl.MplStructure(dt=DT), TRUE, u)
    return u, y + 0.01 * np.random.default_rng(0).standard_normal(u.size)


# --------------------------------------------------------------------------- the limit switch


def test_unlimited_step_is_the_sinh_closed_form():
    params = mpl.MplParams(i_s=[0.1], v_t=[0.2], w=[1.0, 0.4], v_b=-0.6)
    step = 0.9  # f'(0.9) dt = 2 I_S / V_T cosh(4.5) dt = 1.12: past the default cap of 1
    u = np.r_[0.0, step, step]
    unlimited = mpl.MplStructure(dt=DT, limit=False)
    assert np.isinf(mpl.knee_voltage(unlimited, params)).all()
    y, x_end = mpl.simulate(unlimited, params, u)
    x1 = 2 * 0.1 * np.sinh(step / 0.2) * DT  # eq. 5.1, 5.6 from rest at 0
    x2 = x1 + 2 * 0.1 * np.sinh((step - x1) / 0.2) * DT
    assert_allclose(y, [0.6, step + 0.4 * 0.0 + 0.6, step + 0.4 * x1 + 0.6], rtol=1e-14)
    assert_allclose(x_end, [x2], rtol=1e-14)
    limited, _ = mpl.simulate(mpl.MplStructure(dt=DT), params, u)
    assert limited[2] < y[2]  # the limit caps that step's current


def test_limited_and_unlimited_agree_below_the_knee():
    params = mpl.MplParams(i_s=[0.05, 0.3], v_t=[0.2, 0.5], w=[1.0, 0.4, -0.3], v_b=0.2)
    t = np.arange(2000) * DT
    u = 0.5 * np.sin(2 * np.pi * 0.1 * t)
    limited = mpl.MplStructure(n_cells=2, dt=DT)
    y_lim, _ = mpl.simulate(limited, params, u)
    y_free, _ = mpl.simulate(mpl.MplStructure(n_cells=2, dt=DT, limit=False), params, u)
    # the premise: every cell's drive stays inside its knee (the reference run's states)
    x = np.full(2, u[0])
    knee = mpl.knee_voltage(limited, params)
    for value in u:
        assert np.all(np.abs(value - x) < knee)
        _, x = mpl.step(limited, params, x, value)
    assert_allclose(y_free, y_lim, rtol=0, atol=0)  # the same branch, the same arithmetic


def test_unlimited_divergence_is_reported_not_nan():
    params = FAMILY.presets()["table-5.2-fitted"][1]  # f' dt = 2 at |v| = 0.51 (40 Hz)
    t = np.arange(400) * DT
    u = np.sin(2 * np.pi * 2.0 * t)  # 2 Hz: the cell lags by more than the knee
    with pytest.raises(FitDivergedError, match=r"diverged at sample \d+ of 400.*sec\. 5\.3\.3"):
        mpl.simulate(mpl.MplStructure(dt=DT, limit=False), params, u)
    y, _ = mpl.simulate(mpl.MplStructure(dt=DT), params, u)  # limited: bounded
    assert np.all(np.abs(y) <= mpl.output_bound(mpl.MplStructure(dt=DT), params, 1.0))
    with pytest.raises(FitDivergedError, match="diverged at sample"):
        mpl.invert(mpl.MplStructure(dt=DT, limit=False), params, 0.2 * u)


def test_limit_is_saved_and_old_files_load_limited():
    structure = mpl.MplStructure(n_cells=2, dt=DT, limit=False)
    assert mpl.MplStructure.from_dict(structure.to_dict()) == structure
    old = {"n_cells": 2, "dt": DT, "slope_cap": 1.0}
    assert mpl.MplStructure.from_dict(old).limit is True
    with pytest.raises(TypeError, match="limit"):
        mpl.MplStructure(limit="no")


# --------------------------------------------------------------------------- one exact start


def test_fit_starts_exactly_at_init(data, monkeypatch):
    u, y = data
    init = FAMILY.presets()["table-5.2"][1]
    seen = []
    real = kernels.theta_normal_equations
    monkeypatch.setattr(kernels, "theta_normal_equations",
                        lambda *a: seen.append(np.array(a[3])) or real(*a))
    result = mpl_fit.fit_mpl(u, y, mpl.MplStructure(dt=DT), init=init, max_nfev=1,
                             screen_nfev=1)
    assert_allclose(seen[0], init.to_vector(), rtol=0, atol=0)
    assert result.n_starts == 1
    assert result.params == init  # one evaluation: no step taken


def test_fit_from_init_recovers_the_model(data):
    u, y = data
    for limit in (True, False):
        result = mpl_fit.fit_mpl(u, y, mpl.MplStructure(dt=DT, limit=limit),
                                 init=FAMILY.presets()["table-5.2"][1])
        assert result.converged
        # the noise (0.01, 4000 samples) moves the parameters by a few per cent
        assert_allclose(result.params.to_vector(), TRUE.to_vector(), rtol=0.05, atol=0.02)


def test_start_outside_the_box_is_reported_and_clipped():
    structure = mpl.MplStructure(dt=DT)
    start = FAMILY.start_options(structure, FAMILY.presets()["table-5.2-fitted"][1])
    assert isinstance(start, FitStart) and len(start.clipped) == 1
    g = 2 * 1.72e-7 / 0.0307  # below the box's floor 1e-4
    assert f"log_G[1] = {np.log(g):.6g}" in start.clipped[0]
    assert f"starts from {np.log(1e-4):.6g}" in start.clipped[0]
    unlimited = FAMILY.start_options(mpl.MplStructure(dt=DT, limit=False),
                                     FAMILY.presets()["table-5.2-fitted"][1])
    assert unlimited.clipped == ()  # its box reaches G = 1e-8


def test_init_with_another_cell_count_is_refused(data):
    with pytest.raises(ValueError, match="1 cell"):
        mpl_fit.fit_mpl(*data, mpl.MplStructure(n_cells=2, dt=DT),
                        init=FAMILY.presets()["table-5.2"][1])


# --------------------------------------------------------------------------- sum |w| <= B


def _normal_equations(u, y):
    x0 = np.full(1, u[0])

    def one_pass(theta):
        sse, jtj, jtr = kernels.theta_normal_equations(u, y, x0, theta, 1.0, DT)
        return NormalEquations(0.5 * sse, jtj, jtr)

    return one_pass


def test_large_bound_gives_the_unconstrained_fit(data):
    u, y = data
    free = mpl_fit.fit_mpl(u, y, mpl.MplStructure(dt=DT))
    start = FAMILY.presets()["table-5.2"][1].to_vector()  # not the optimum
    sol = minimise_with_weight_sum(_normal_equations(u, y), start,
                                   mpl_fit.fit_box(mpl.MplStructure(dt=DT)), np.array([2, 3]),
                                   100.0)
    assert sol.converged and not sol.active
    assert_allclose(sol.cost, free.cost, rtol=1e-6)
    assert_allclose(sol.theta, free.theta, rtol=1e-4, atol=1e-5)


def test_small_bound_is_active_and_kkt_holds(data):
    u, y = data
    structure = mpl.MplStructure(dt=DT)
    free = mpl_fit.fit_mpl(u, y, structure)
    bound = 1.5  # the free fit has sum |w| = 2.34
    result = mpl_fit.fit_mpl(u, y, structure, weight_sum_max=bound)
    w = result.params.w
    assert_allclose(np.abs(w).sum(), bound, rtol=1e-8)
    assert result.cost >= free.cost
    assert "active" in result.message and result.converged
    # KKT: grad_theta(0.5 SSE) = -lambda d(sum |w|)/d theta with lambda >= 0; the nonlinear
    # coordinates are free (inside the box), so their gradient vanishes
    grad = _normal_equations(u, y)(result.theta).jtr
    lam = -grad[2:4] @ np.sign(w) / 2
    assert lam > 0
    assert_allclose(grad[2:4], -lam * np.sign(w), rtol=1e-4)
    assert_allclose(grad[[0, 1, 4]], 0.0, atol=1e-4 * lam)


def test_constraint_refuses_a_robust_loss(data):
    with pytest.raises(ValueError, match="SSE"):
        mpl_fit.fit_mpl(*data, mpl.MplStructure(dt=DT), weight_sum_max=1.5, loss="huber",
                        solver="trf")


def test_unlimited_cells_report_the_would_be_knees_and_run_the_sinh():
    params = mpl.MplParams(i_s=[0.1], v_t=[0.2], w=[1.0, 0.4], v_b=-0.6)
    limited = FAMILY.cells(mpl.MplStructure(dt=DT), params)
    free = FAMILY.cells(mpl.MplStructure(dt=DT, limit=False), params)
    assert_allclose(free.knees, limited.knees, rtol=0)  # finite: where the cap would act
    v = np.array([1.5 * limited.knees[0, 1]])  # beyond the knee
    assert_allclose(free.current(v), 2 * 0.1 * np.sinh(v / 0.2), rtol=1e-14)
    assert free.current(v)[0] > limited.current(v)[0]
