"""Recursive least squares with forgetting equals the batch weighted least squares it recurses."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.live._rls import rls_bound, rls_start, rls_update

P = 3
N = 40


def data(seed: int = 0):
    rng = np.random.default_rng(seed)
    phi = rng.standard_normal((N, P)) * [1.0, 3.0, 0.2]
    r = phi @ [0.5, -1.0, 2.0] + 0.1 * rng.standard_normal(N)
    return phi, r


def recursive(phi, r, theta0, std, lam):
    state = rls_start(theta0, std)
    for k in range(phi.shape[0]):
        state = rls_update(state, phi[k], r[k], lam)
    return state


def batch(phi, r, theta0, std, lam):
    """Weighted least squares on the samples plus the prior as pseudo-observations, solved
    from scratch (np.linalg.lstsq): sample k weighs lam^(n-k), the prior lam^n / std^2."""
    n = phi.shape[0]
    w = np.sqrt(lam ** (n - 1 - np.arange(n)))  # the last sample (k = n - 1) weighs 1
    prior_w = np.sqrt(lam ** n) / std
    a = np.vstack([phi * w[:, None], np.diag(prior_w)])
    b = np.concatenate([r * w, prior_w * theta0])
    theta = np.linalg.lstsq(a, b, rcond=None)[0]
    return theta, np.linalg.inv(a.T @ a)


@pytest.mark.parametrize("lam", [1.0, 0.97, 0.8])
@pytest.mark.parametrize("n", [1, 2, 5, N])
def test_rls_equals_batch_weighted_least_squares(lam, n):
    phi, r = data()
    theta0, std = np.array([0.2, 0.0, -1.0]), np.array([2.0, 0.5, 10.0])
    got = recursive(phi[:n], r[:n], theta0, std, lam)
    theta, cov = batch(phi[:n], r[:n], theta0, std, lam)
    # tolerance: rounding of a few dozen rank-one updates of a well-conditioned 3x3 system
    assert_allclose(got.theta, theta, rtol=1e-10, atol=1e-10)
    assert_allclose(got.cov, cov, rtol=1e-10, atol=1e-12)
    assert got.n_updates == n


def test_with_a_vague_prior_and_no_forgetting_rls_is_ordinary_least_squares():
    phi, r = data(1)
    got = recursive(phi, r, np.zeros(P), np.full(P, 1e4), 1.0)
    plain = np.linalg.lstsq(phi, r, rcond=None)[0]
    # the prior's pull is ~ 1 / (std^2 * sum phi^2) ~ 1e-10 relative here
    assert_allclose(got.theta, plain, rtol=1e-8)


def test_forgetting_follows_a_jump_that_plain_least_squares_averages():
    rng = np.random.default_rng(3)
    phi = rng.standard_normal((200, 2))
    theta_true = np.where(np.arange(200)[:, None] < 100, [1.0, 0.0], [1.5, 0.3])
    r = np.sum(phi * theta_true, axis=1)
    forgetting = recursive(phi, r, np.zeros(2), np.ones(2), 0.9).theta
    remembering = recursive(phi, r, np.zeros(2), np.ones(2), 1.0).theta
    # noise-free: with lam = 0.9 the first half weighs 0.9^100 ~ 3e-5 of the second
    assert_allclose(forgetting, [1.5, 0.3], atol=1e-3)
    assert np.abs(remembering - [1.5, 0.3]).max() > 0.1


def test_the_state_is_immutable_and_the_covariance_symmetric():
    phi, r = data(2)
    state = recursive(phi, r, np.zeros(P), np.ones(P), 0.9)
    assert np.array_equal(state.cov, state.cov.T)
    with pytest.raises(ValueError):
        state.theta[0] = 1.0


def test_a_bad_prior_is_refused():
    with pytest.raises(ValueError, match="prior_std"):
        rls_start(np.zeros(2), np.array([1.0, 0.0]))


def test_the_bound_scales_p_down_to_the_trace_and_keeps_theta():
    phi, r = data(4)
    state = recursive(phi, r, np.zeros(P), np.ones(P), 0.5)
    trace = np.trace(state.cov)
    assert rls_bound(state, 2 * trace) is state
    bounded = rls_bound(state, 0.25 * trace)
    assert_allclose(np.trace(bounded.cov), 0.25 * trace, rtol=1e-14)
    assert_allclose(bounded.cov, 0.25 * state.cov, rtol=1e-14)
    assert np.array_equal(bounded.theta, state.theta) and bounded.n_updates == state.n_updates


def test_without_the_bound_one_repeated_regressor_winds_p_up():
    # the case the bound is for: the same regressor again and again, lam < 1
    state = rls_start(np.zeros(2), np.ones(2))
    for _ in range(200):
        state = rls_update(state, np.array([1.0, 1.0]), 0.0, 0.9)
    assert np.trace(state.cov) > 1e8  # ~0.9^-200 along (1, -1)
