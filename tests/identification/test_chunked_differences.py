"""Chunked forward-difference normal equations: chunked == whole, and == the dense Jacobian's."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.identification import ChunkedDifferences, dense_normal_equations
from hystkit.models import chua
from hystkit.models.chua.box import fit_bounds
from hystkit.models.chua.fit import default_starts

STRUCTURE = chua.ChuaStructure(n_elements=2, dt=0.025)


def _data(n=3000, seed=4):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * STRUCTURE.dt
    u = np.sin(2 * np.pi * 0.3 * t) + 0.2 * rng.normal(size=n)
    return u / np.max(np.abs(u)), np.tanh(1.5 * np.roll(u, 3))


def _chunked(u, y, chunk):
    def run(theta, u_chunk, x):
        return chua.simulate(STRUCTURE, chua.ChuaParams.from_vector(theta, 2), u_chunk, x)
    return ChunkedDifferences(run, u, y, *fit_bounds(STRUCTURE), chunk=chunk)


@pytest.fixture(scope="module")
def theta():
    return default_starts(STRUCTURE, 1.0)[3].to_vector()


@pytest.mark.parametrize("chunk", [1, 777, 1000])  # single samples, ragged, even split
def test_chunked_equals_whole(theta, chunk):
    """A split run equals the whole run, so only the order of the sums differs (1e-12)."""
    u, y = _data()
    whole = _chunked(u, y, u.size).normal_equations(theta)
    parts = _chunked(u, y, chunk).normal_equations(theta)
    assert_allclose(parts.cost, whole.cost, rtol=1e-12)
    assert_allclose(parts.jtj, whole.jtj, rtol=1e-12, atol=1e-12 * np.max(np.abs(whole.jtj)))
    assert_allclose(parts.jtr, whole.jtr, rtol=1e-12, atol=1e-12 * np.max(np.abs(whole.jtr)))
    assert_allclose(_chunked(u, y, chunk).cost(theta), whole.cost, rtol=1e-12)


def test_chunked_equals_the_dense_difference_jacobian(theta):
    """Same steps as the dense '2-point' path on the whole residual: the same J^T J, J^T r."""
    u, y = _data()

    def residual(th):
        return chua.simulate(STRUCTURE, chua.ChuaParams.from_vector(th, 2), u)[0] - y

    dense = dense_normal_equations(residual, "2-point", *fit_bounds(STRUCTURE))(theta)
    chunked = _chunked(u, y, 1000).normal_equations(theta)
    assert_allclose(chunked.cost, dense.cost, rtol=1e-12)
    assert_allclose(chunked.jtj, dense.jtj, rtol=1e-10, atol=1e-10 * np.max(np.abs(dense.jtj)))
    assert_allclose(chunked.jtr, dense.jtr, rtol=1e-10, atol=1e-10 * np.max(np.abs(dense.jtr)))


def test_difference_jacobian_approximates_the_derivative(theta):
    """Forward differences with sqrt(eps) steps: J^T r agrees with central differences of the
    cost to ~1e-6 relative (the truncation error of a forward difference, O(sqrt(eps)))."""
    u, y = _data(1500)
    problem = _chunked(u, y, 500)
    grad = problem.normal_equations(theta).jtr
    h = 1e-6
    central = np.array([(problem.cost(theta + h * e) - problem.cost(theta - h * e)) / (2 * h)
                        for e in np.eye(theta.size)])
    assert_allclose(grad, central, rtol=1e-4, atol=1e-6 * np.max(np.abs(central)))
