"""The trust-region kernels (``_trust_region_steps``) against scipy's ``trf`` helpers, one
iteration at a time: the scaled problem from ``(J^T J, J^T r)`` and the step proposed for a
radius equal scipy's from ``J`` itself, whether the step stays inside the box or hits a bound
(reflection and scaled-gradient candidates); normal equations that are not finite are refused.
Issue 29 moved the kernels' factorisations out of numba."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.linalg import svd
from scipy.optimize._lsq.common import (
    CL_scaling_vector,
    make_strictly_feasible,
    solve_lsq_trust_region,
)
from scipy.optimize._lsq.trf import select_step

from hystkit.identification._trust_region_steps import propose, scaled_problem


def _problem(seed: int, half_width: float):
    """A well-conditioned random Jacobian, a gradient (any: the kernels see ``J^T J`` and
    ``J^T r`` only) and a point strictly inside a box of about the given half width."""
    rng = np.random.default_rng(seed)
    p = int(rng.integers(2, 12))
    jac = rng.normal(size=(40, p)) * np.exp(rng.uniform(-2, 2, p))
    g = rng.normal(size=p) * np.exp(rng.uniform(-2, 2, p))
    x = rng.normal(size=p)
    lb = x - rng.uniform(0.2, 1.0, p) * half_width
    ub = x + rng.uniform(0.2, 1.0, p) * half_width
    return jac, g, x, lb, ub


def _scipy_iteration(jac, g, x, lb, ub, scale_inv, delta, theta):
    """One iteration of scipy's trf_bounds from J (its code, inlined; ``U^T f`` from the
    gradient: ``J_aug^T f_aug = g_h``)."""
    p = x.size
    v, dv = CL_scaling_vector(x, g, lb, ub)
    v[dv != 0] *= scale_inv[dv != 0]
    d = v ** 0.5 / scale_inv
    diag_h = g * dv / scale_inv
    g_h = d * g
    j_h = jac * d
    _, s, vt = svd(np.vstack([j_h, np.diag(diag_h ** 0.5)]), full_matrices=False)
    uf = (vt @ g_h) / s
    # m = 2p rows for the Gauss-Newton test, as the module says it uses
    p_h, alpha, _ = solve_lsq_trust_region(p, 2 * p, uf, s, vt.T, delta, initial_alpha=0.0)
    trust_region_point = x + d * p_h  # before select_step, which scales p_h in place
    step, step_h, predicted = select_step(x, j_h, diag_h, g_h, d * p_h, p_h, d, delta, lb, ub,
                                          theta)
    x_new = make_strictly_feasible(x + step, lb, ub, rstep=0)
    return (x_new, np.linalg.norm(step), np.linalg.norm(step_h), predicted, alpha, s ** 2,
            trust_region_point)


CASES = [(10.0, 0.5), (10.0, 50.0), (0.05, 5.0)]


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("half_width, delta", CASES)
def test_one_iteration_equals_scipy_trf(seed, half_width, delta):
    """A small radius in a wide box (the trust-region step), a large one, and a narrow box
    that the trust-region step leaves in some seeds (scipy's choice among the step cut at the
    bound, its reflection and the scaled gradient)."""
    jac, jtr, x, lb, ub = _problem(seed, half_width)
    jtj = jac.T @ jac
    scale_inv = np.sqrt(np.diag(jtj))
    theta = 0.995
    d, diag_h, g_h, h_h, eig, vecs, sg, g_norm = scaled_problem(x, jtj, jtr, lb, ub,
                                                                scale_inv.copy())
    got = propose(x, h_h, diag_h, g_h, eig, vecs, sg, d, delta, 0.0, lb, ub, theta)
    want = _scipy_iteration(jac, jtr, x, lb, ub, scale_inv, delta, theta)
    assert_allclose(eig, want[5], rtol=1e-9)
    assert_allclose(got[0], want[0], rtol=1e-9, atol=1e-12)
    assert_allclose(got[1:], want[1:5], rtol=1e-8, atol=1e-14)
    assert_allclose(h_h, d[:, None] * jtj * d[None, :], rtol=1e-15)
    v, _ = CL_scaling_vector(x, jtr, lb, ub)
    assert g_norm == np.max(np.abs(jtr * v))


def test_the_cases_hold_both_branches():
    """The comparisons above see trust-region steps that stay inside the box and ones that
    leave it (where the reflection and the scaled gradient compete)."""
    left = {}
    for half_width, delta in CASES:
        left[half_width, delta] = 0
        for seed in range(12):
            jac, g, x, lb, ub = _problem(seed, half_width)
            point = _scipy_iteration(jac, g, x, lb, ub, np.sqrt(np.diag(jac.T @ jac)), delta,
                                     0.995)[6]
            left[half_width, delta] += not np.all((lb <= point) & (point <= ub))
    assert left[10.0, 0.5] == 0
    assert left[0.05, 5.0] >= 3


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_normal_equations_that_are_not_finite_are_refused(bad):
    jac, jtr, x, lb, ub = _problem(0, 10.0)
    jtj = jac.T @ jac
    scaled_problem(x, jtj, jtr, lb, ub, np.ones(x.size))  # finite: no error
    jtj[0, 1] = jtj[1, 0] = bad
    with pytest.raises(np.linalg.LinAlgError, match="infs or NaNs"):
        scaled_problem(x, jtj, jtr, lb, ub, np.ones(x.size))
