"""The solvers on normal equations (trust-region reflective, projected Levenberg-Marquardt) on
problems with known answers."""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import least_squares, lsq_linear

from hystkit.identification import NormalEquations, solve_lm
from hystkit.identification._trust_region import solve_trust_region
from hystkit.identification._trust_region_steps import square_root

SOLVERS = pytest.mark.parametrize("solve", [solve_trust_region, solve_lm], ids=["tr", "lm"])


def _linear(a, b):
    """Normal equations of r = A x - b."""
    def normal_equations(x):
        r = a @ x - b
        return NormalEquations(0.5 * float(r @ r), a.T @ a, a.T @ r)
    return normal_equations


def _rosenbrock(x):
    """Residuals of Rosenbrock's function as least squares, and their Jacobian."""
    r = np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]])
    j = np.array([[-20.0 * x[0], 10.0], [-1.0, 0.0]])
    return r, j


def _rosenbrock_normal(x):
    r, j = _rosenbrock(x)
    return NormalEquations(0.5 * float(r @ r), j.T @ j, j.T @ r)


@SOLVERS
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_bounded_linear_least_squares_matches_lsq_linear(seed, solve):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(60, 6)) * np.logspace(0, 2, 6)  # columns scaled over two decades
    b = rng.normal(size=60) * 10.0
    lower, upper = np.full(6, -0.05), np.full(6, 0.05)  # tight enough that bounds are active
    ref = lsq_linear(a, b, bounds=(lower, upper), tol=1e-14)
    sol = solve(_linear(a, b), np.zeros(6), lower, upper, max_nfev=500)
    assert np.any(np.isclose(ref.x, lower) | np.isclose(ref.x, upper))
    assert sol.success, sol.message
    # a convex problem: the same minimiser; the cost to 1e-10 relative (ftol = 1e-8 stops the
    # solver within ~1e-8 of the optimum in cost, which is second order in x)
    assert_allclose(sol.x, ref.x, atol=1e-6)
    assert_allclose(sol.cost, ref.cost, rtol=1e-8)


@SOLVERS
def test_unbounded_linear_least_squares_is_the_lstsq_solution(solve):
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=(40, 4)), rng.normal(size=40)
    inf = np.full(4, np.inf)
    sol = solve(_linear(a, b), np.ones(4), -inf, inf, ftol=1e-15, xtol=1e-15, gtol=1e-12)
    assert_allclose(sol.x, np.linalg.lstsq(a, b, rcond=None)[0], rtol=1e-8, atol=1e-10)


@SOLVERS
def test_rosenbrock_reaches_its_minimum(solve):
    inf = np.full(2, np.inf)
    sol = solve(_rosenbrock_normal, np.array([-1.2, 1.0]), -inf, inf)
    assert sol.success, sol.message
    assert_allclose(sol.x, [1.0, 1.0], atol=1e-6)  # closed form: the minimum at (1, 1), cost 0


@SOLVERS
def test_bounded_rosenbrock_matches_scipy_trf(solve):
    lower, upper = np.array([-2.0, -2.0]), np.array([0.5, 2.0])  # cuts off the minimum (1, 1)
    ref = least_squares(lambda x: _rosenbrock(x)[0], [-1.2, 1.0],
                        jac=lambda x: _rosenbrock(x)[1], bounds=(lower, upper), method="trf",
                        x_scale="jac", ftol=1e-14, xtol=1e-14, gtol=1e-14)
    sol = solve(_rosenbrock_normal, np.array([-1.2, 1.0]), lower, upper)
    assert sol.success, sol.message
    assert_allclose(sol.x, ref.x, atol=1e-6)
    assert_allclose(sol.x, [0.5, 0.25], atol=1e-6)  # on x0 = 0.5 the best x1 is x0^2
    assert_allclose(sol.cost, ref.cost, rtol=1e-8)


@SOLVERS
def test_judging_trials_by_cost_alone_finds_the_same_point(solve):
    calls = {"cost": 0}

    def cost(x):
        calls["cost"] += 1
        return _rosenbrock_normal(x).cost

    inf = np.full(2, np.inf)
    sol = solve(_rosenbrock_normal, np.array([-1.2, 1.0]), -inf, inf, cost=cost)
    assert sol.success and calls["cost"] > 0
    # the start's cost comes with its normal equations; every other cost is judged alone
    assert sol.nfev == calls["cost"] + 1 and sol.n_runs == calls["cost"] + sol.njev
    assert_allclose(sol.x, [1.0, 1.0], atol=1e-6)


@SOLVERS
def test_an_exhausted_budget_is_not_convergence(solve):
    inf = np.full(2, np.inf)
    sol = solve(_rosenbrock_normal, np.array([-1.2, 1.0]), -inf, inf, max_nfev=3)
    assert sol.status == 0 and not sol.success and sol.nfev == 3
    assert "budget" in sol.message


def test_a_wrong_gradient_stalls_and_says_so():
    """LM: every step along the negated gradient raises the cost: with xtol off, nothing can stop
    the solver but the damping limit, and the result must not claim convergence."""
    def uphill(x):
        ne = _rosenbrock_normal(x)
        return NormalEquations(ne.cost, ne.jtj, -ne.jtr)

    inf = np.full(2, np.inf)
    sol = solve_lm(uphill, np.array([-1.2, 1.0]), -inf, inf, xtol=0.0)
    assert sol.status == -2 and not sol.success and "stalled" in sol.message
    assert_allclose(sol.x, [-1.2, 1.0])  # no step was accepted


@SOLVERS
def test_a_non_finite_start_is_reported(solve):
    def nan_cost(x):
        return NormalEquations(np.nan, np.eye(2), np.zeros(2))

    sol = solve(nan_cost, np.zeros(2), np.full(2, -1.0), np.full(2, 1.0))
    assert sol.status == -3 and not sol.success and sol.cost == np.inf


@SOLVERS
def test_column_norms_are_those_of_the_jacobian_at_the_optimum(solve):
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(30, 3)), rng.normal(size=30)
    inf = np.full(3, np.inf)
    sol = solve(_linear(a, b), np.zeros(3), -inf, inf)
    assert_allclose(sol.column_norms, np.linalg.norm(a, axis=0), rtol=1e-12)


def _decay(theta, t):
    """Residual pieces of y = a exp(-b t) + c: the model and its Jacobian."""
    a, b, c = theta
    e = np.exp(-b * t)
    return a * e + c, np.column_stack([e, -a * t * e, np.ones_like(t)])


@pytest.mark.parametrize("upper_b", [np.inf, 0.8])  # free, and the decay rate held by a bound
def test_trust_region_takes_scipy_trf_s_path(upper_b):
    """The port replaces the SVD of J by the eigenvalues of J^T J: same steps, same stop."""
    t = np.linspace(0.0, 10.0, 200)
    y = 2.0 * np.exp(-1.3 * t) + 0.5 + 0.01 * np.random.default_rng(0).normal(size=t.size)
    lower, upper = np.array([0.0, 0.0, -1.0]), np.array([10.0, upper_b, 1.0])
    x0 = np.array([1.0, 0.1, 0.0])
    ref = least_squares(lambda th: _decay(th, t)[0] - y, x0, jac=lambda th: _decay(th, t)[1],
                        bounds=(lower, upper), method="trf", x_scale="jac")

    def normal_equations(theta):
        out, j = _decay(theta, t)
        r = out - y
        return NormalEquations(0.5 * float(r @ r), j.T @ j, j.T @ r)

    sol = solve_trust_region(normal_equations, x0, lower, upper)
    assert sol.status == ref.status and sol.nfev == ref.nfev and sol.njev == ref.njev
    assert_allclose(sol.x, ref.x, rtol=1e-9)
    assert_allclose(sol.cost, ref.cost, rtol=1e-12)


def test_square_root_of_a_singular_matrix_reproduces_it():
    """J^T J with a zero column has no Cholesky factor: R comes from the eigendecomposition,
    and R^T R still equals J^T J (to rounding of the largest entry)."""
    rng = np.random.default_rng(3)
    j = rng.normal(size=(30, 4))
    j[:, 2] = 0.0
    jtj = j.T @ j
    with pytest.raises(np.linalg.LinAlgError):
        np.linalg.cholesky(jtj)
    root = square_root(jtj)
    assert_allclose(root.T @ root, jtj, rtol=0, atol=1e-12 * np.max(np.abs(jtj)))


def test_trust_region_with_a_parameter_that_does_not_act_matches_scipy_trf():
    """A coordinate with a zero Jacobian column (rank-deficient J^T J): the fit of the others
    is scipy trf's (where the idle coordinate ends is arbitrary, for trf too)."""
    rng = np.random.default_rng(4)
    a = rng.normal(size=(50, 4))
    a[:, 1] = 0.0
    b = rng.normal(size=50)
    x0 = np.array([0.1, 0.3, -0.2, 0.0])
    lower, upper = np.full(4, -1.0), np.full(4, 1.0)
    ref = least_squares(lambda x: a @ x - b, x0, jac=lambda x: a, bounds=(lower, upper),
                        method="trf", x_scale="jac")
    sol = solve_trust_region(_linear(a, b), x0, lower, upper)
    assert sol.success, sol.message
    assert lower[1] < sol.x[1] < upper[1]
    # convex in the acting coordinates: same minimiser and cost as trf, to its stopping rules
    acting = [0, 2, 3]
    assert_allclose(sol.x[acting], ref.x[acting], atol=1e-4)
    assert_allclose(sol.cost, ref.cost, rtol=1e-8)


@pytest.mark.parametrize("first", [1, 4, 9])
def test_a_resumed_trust_region_solve_is_the_uninterrupted_one(first):
    """Stopped on its budget and resumed from its state, the solve takes the same steps as one
    that was never stopped (bit for bit), and does not run its last point again."""
    lower, upper = np.array([-2.0, -2.0]), np.array([0.5, 2.0])
    runs = []

    def counted(x):
        runs.append(x.copy())
        return _rosenbrock_normal(x)

    whole = solve_trust_region(counted, np.array([-1.2, 1.0]), lower, upper, max_nfev=30)
    n_whole = len(runs)
    runs.clear()
    part = solve_trust_region(counted, np.array([-1.2, 1.0]), lower, upper, max_nfev=first)
    assert part.status == 0 and len(runs) == first
    rest = solve_trust_region(counted, None, lower, upper, max_nfev=30 - first,
                              resume=part.state)
    assert len(runs) == n_whole == part.n_runs + rest.n_runs
    assert rest.status == whole.status and rest.cost == whole.cost
    assert np.array_equal(rest.x, whole.x)
