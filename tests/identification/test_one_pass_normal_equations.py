"""One-pass normal equations of the compiled kernels equal those of the dense Jacobian."""

import numpy as np
import pytest
from numba import njit
from numpy.testing import assert_allclose

from hystkit.models import mpl, mpl_poly
from hystkit.models.mpl import kernels as mpl_kernels
from hystkit.models.mpl_poly.fit import normal_equations, random_params


def _input(n, seed):
    t = np.arange(n) * 0.025
    rng = np.random.default_rng(seed)
    u = np.sin(2 * np.pi * 0.5 * t) + 0.3 * rng.normal(size=n)
    return u / np.max(np.abs(u))


def _dense(y_model, jac, target):
    r = y_model - target
    return float(r @ r), jac.T @ jac, jac.T @ r


def _assert_same(one_pass, dense):
    """To 1e-10 relative: the sums differ only in the order of floating-point additions."""
    sse, jtj, jtr = one_pass
    sse_ref, jtj_ref, jtr_ref = dense
    assert_allclose(sse, sse_ref, rtol=1e-10)
    assert_allclose(jtj, jtj_ref, rtol=1e-10, atol=1e-10 * np.max(np.abs(jtj_ref)))
    assert_allclose(jtr, jtr_ref, rtol=1e-10, atol=1e-10 * np.max(np.abs(jtr_ref)))
    assert_allclose(jtj, jtj.T, rtol=0, atol=0)


@pytest.mark.parametrize("n_cells", [1, 3])
@pytest.mark.parametrize("rate", [0.05, 0.95])  # cells far below the cap / near it (knee)
def test_mpl_one_pass_equals_the_dense_jacobian(n_cells, rate):
    structure = mpl.MplStructure(n_cells=n_cells, dt=0.025)
    cap = structure.slope_cap / structure.dt
    rng = np.random.default_rng(n_cells)
    v_t = rng.uniform(0.1, 0.5, n_cells)
    g = rate * cap * rng.uniform(0.5, 1.0, n_cells)
    params = mpl.MplParams(i_s=0.5 * g * v_t, v_t=v_t, w=rng.uniform(-1, 1, n_cells + 1),
                           v_b=0.1)
    u = _input(3000, n_cells)
    target = np.roll(u, 7) ** 3
    knee = mpl.knee_voltage(structure, params)
    args = (np.full(n_cells, u[0]), params.i_s, params.v_t, params.w, params.v_b, knee, cap,
            structure.dt)
    y_model, jac = mpl_kernels.simulate_with_jacobian(u, *args)
    # cell states (the output with w = e_k, V_b = 0): both branches of the limited resistor
    # (eq. 5.29) must be exercised when the rate is near the cap
    states = np.column_stack([
        mpl_kernels.simulate(u, args[0], params.i_s, params.v_t, np.eye(n_cells + 1)[k + 1],
                             0.0, knee, cap, structure.dt)[0] for k in range(n_cells)])
    share_beyond = np.mean(np.abs(u[:, None] - states) > knee)
    assert share_beyond > 0.2 if rate > 0.5 else share_beyond < 0.05
    _assert_same(mpl_kernels.normal_equations(u, target, *args), _dense(y_model, jac, target))


@pytest.mark.parametrize("limit", [True, False])
@pytest.mark.parametrize("n_cells", [1, 2])
def test_mpl_poly_one_pass_equals_the_dense_jacobian(n_cells, limit):
    """From rest (the start moves with the parameters), with and without the Euler limit."""
    structure = mpl_poly.MplPolyStructure(n_cells=n_cells, dt=0.025, limit=limit)
    rng = np.random.default_rng(10 + n_cells)
    params = random_params(structure, rng)
    u = _input(3000, n_cells)
    target = np.tanh(2 * np.roll(u, 5))
    y_model, jac = mpl_poly.simulate_with_jacobian(structure, params, u)
    assert np.all(np.isfinite(jac))
    ne = normal_equations(structure, params, u, target)
    _assert_same((2 * ne.cost, ne.jtj, ne.jtr), _dense(y_model, jac, target))


def test_mpl_poly_one_pass_rejects_a_diverging_run():
    """Without the limit a steep cubic overshoots each Euler step and runs away: infinite
    cost, where the dense run gives NaN."""
    structure = mpl_poly.MplPolyStructure(n_cells=1, dt=0.025, limit=False)
    params = mpl_poly.MplPolyParams(f=[[0.0, 1.0, 0.0, 1e3]], g=[0.0, 1.0, 0.0, 0.0],
                                    w=[1.0, 1.0])
    u = 3 * _input(500, 0)
    assert not np.all(np.isfinite(mpl_poly.simulate_with_jacobian(structure, params, u)[0]))
    assert normal_equations(structure, params, u, u).cost == np.inf


def test_mpl_fit_sensitivity_is_the_dense_column_norms():
    """FitResult.sensitivity comes from diag(J^T J): the column norms of the dense Jacobian."""
    structure = mpl.MplStructure(n_cells=2, dt=0.025)
    u = _input(2000, 3)
    result = mpl.fit_mpl(u, np.tanh(2 * np.roll(u, 4)), structure)
    p = result.params
    _, jac = mpl_kernels.simulate_with_jacobian(
        u, np.full(2, u[0]), p.i_s, p.v_t, p.w, p.v_b, mpl.knee_voltage(structure, p),
        structure.slope_cap / structure.dt, structure.dt)
    assert_allclose(result.sensitivity, np.linalg.norm(jac, axis=0), rtol=1e-10)


@njit
def _sinh_cosh_array(a):
    sh, ch = np.empty(a.size), np.empty(a.size)
    for i in range(a.size):
        sh[i], ch[i] = mpl_kernels.sinh_cosh(a[i])
    return sh, ch


def test_one_exp_sinh_cosh_is_within_a_few_ulp():
    """Against sinh and cosh in extended precision (x87 long double, 64-bit mantissa): 2 ulp
    covers the exp's own rounding, 1 / e, the subtraction beyond |a| = 0.5 (coth 0.5 = 2.2)
    and the series below it."""
    a = np.r_[np.linspace(-20.0, 20.0, 40_001), np.geomspace(1e-300, 20.0, 20_000)]
    a = np.r_[a, -a[40_001:]]
    sh, ch = _sinh_cosh_array(a)
    exact = a.astype(np.longdouble)
    nonzero = a != 0
    eps = np.finfo(float).eps
    assert np.max(np.abs(sh[nonzero] / np.sinh(exact[nonzero]) - 1)) < 2 * eps
    assert np.max(np.abs(ch / np.cosh(exact) - 1)) < 2 * eps
    assert _sinh_cosh_array(np.array([0.0, -0.0]))[0].tolist() == [0.0, 0.0]
    sh, ch = _sinh_cosh_array(np.array([-800.0, 800.0]))  # overflow as libm: signed inf
    assert sh.tolist() == [-np.inf, np.inf] and ch.tolist() == [np.inf, np.inf]


@pytest.mark.parametrize("rate", [0.05, 0.95])
def test_mpl_one_pass_cost_is_the_simulated_cost(rate):
    """The one-pass kernel's sinh differs from simulate's (libm) by ulps: over 20 000 steps the
    SSE still agrees to 1e-12 relative (rounding, not a different model; measured 5e-15)."""
    n_cells = 3
    structure = mpl.MplStructure(n_cells=n_cells, dt=0.025)
    cap = structure.slope_cap / structure.dt
    v_t = np.array([0.05, 0.3, 2.0])
    params = mpl.MplParams(i_s=0.5 * rate * cap * v_t * np.array([0.5, 0.8, 1.0]), v_t=v_t,
                           w=[0.7, -0.4, 0.9, 0.3], v_b=0.05)
    u = _input(20_000, 7)
    target = np.roll(u, 7) ** 3
    y_model, _ = mpl.simulate(structure, params, u)
    sse = mpl_kernels.normal_equations(
        u, target, np.full(n_cells, u[0]), params.i_s, params.v_t, params.w, params.v_b,
        mpl.knee_voltage(structure, params), cap, structure.dt)[0]
    assert_allclose(sse, np.sum((y_model - target) ** 2), rtol=1e-12)


def test_mpl_one_pass_at_optimiser_coordinates():
    """theta_normal_equations == normal_equations of MplParams.from_vector(theta): the
    compiled unpacking (exp, knee) may differ from NumPy's by an ulp, hence 1e-10."""
    structure = mpl.MplStructure(n_cells=3, dt=0.025)
    rng = np.random.default_rng(8)
    u = _input(3000, 8)
    target = np.tanh(2 * np.roll(u, 3))
    x0 = np.full(3, u[0])
    for _ in range(4):
        theta = mpl.fit.random_params(structure, rng).to_vector()
        params = mpl.MplParams.from_vector(theta, 3)
        direct = mpl_kernels.normal_equations(
            u, target, x0, params.i_s, params.v_t, params.w, params.v_b,
            mpl.knee_voltage(structure, params), structure.slope_cap / structure.dt,
            structure.dt)
        _assert_same(mpl_kernels.theta_normal_equations(u, target, x0, theta,
                                                        structure.slope_cap, structure.dt),
                     direct)


@pytest.mark.parametrize("p", [1, 2, 3, 4, 11, 12])  # odd and even: pairs and a last column
@pytest.mark.parametrize("m", [1, 7, mpl_kernels.NORMAL_BLOCK])
def test_fold_block_adds_the_upper_triangle_of_c_ct(p, m):
    rng = np.random.default_rng(p * 1000 + m)
    cols = rng.normal(size=(p, mpl_kernels.NORMAL_BLOCK))  # columns past m must not count
    res = rng.normal(size=mpl_kernels.NORMAL_BLOCK)
    jtj, jtr = np.ones((p, p)), np.ones(p)  # the fold adds to what is there
    mpl_kernels.fold_block(cols, res, m, jtj, jtr)
    c = cols[:, :m]
    upper = np.triu_indices(p)
    # sums of m products in another order than BLAS: 1e-12 relative to the terms' scale
    assert_allclose(jtj[upper], 1.0 + (c @ c.T)[upper], rtol=1e-12, atol=1e-12 * m)
    assert np.all(jtj[np.tril_indices(p, -1)] == 1.0)  # the lower triangle is left alone
    assert_allclose(jtr, 1.0 + c @ res[:m], rtol=1e-12, atol=1e-12 * m)
