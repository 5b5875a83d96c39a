"""random_params of the pi family: accepted by Params, inside the stated domain, seeded,
and bounded by sum |w_S| (sum |w_H| + sum |w_K| + |b|) for |u| <= 1."""

import numpy as np
import pytest

from hystkit.models import get_family
from hystkit.models.pi import MIN_SLOPE, inverse_superposition, not_invertible_reason

FAMILY = get_family("pi")


def _sine_steps(n: int = 2000, dt: float = 0.025) -> np.ndarray:
    t = np.arange(n) * dt
    u = 0.9 * np.sin(2 * np.pi * np.cumsum(0.05 * 20.0 ** (t / t[-1])) * dt)
    u[750:850], u[850:950], u[950:1050] = 1.0, -1.0, 0.3  # steps and reversals
    return u


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain_and_reproducible(size):
    structure = FAMILY.make_structure(0.025, size)
    a = [FAMILY.random_params(structure, np.random.default_rng(7)) for _ in range(2)]
    assert a[0] == a[1]
    assert FAMILY.random_params(structure, np.random.default_rng(8)) != a[0]
    rng = np.random.default_rng(3)
    for _ in range(50):
        p = FAMILY.random_params(structure, rng)
        assert FAMILY.Params.from_dict(p.to_dict()) == p  # the constructor accepts it
        m = p.n_deadzone
        k = np.arange(1, m + 1) / (m + 1)
        d_inv, ws_inv = inverse_superposition(p.d_s, p.w_s)  # an involution: back to S^-1
        np.testing.assert_allclose(d_inv, np.r_[-k[::-1], 0.0, k], atol=1e-12)
        slopes = np.r_[np.cumsum(ws_inv[m::-1]), np.cumsum(ws_inv[m:])]  # S^-1 slopes
        assert np.all(slopes >= MIN_SLOPE * (1 - 1e-9)) and np.all(slopes <= 1 / MIN_SLOPE * (1 + 1e-9))
        assert np.all(np.abs(p.w_k) <= 1) and abs(p.b) <= 1
        # Kuhnen's condition: every loading slope exceeds the total negative creep by MIN_SLOPE
        sign = np.sign(p.w_h[0])
        w_minus = np.sum(np.maximum(-sign * p.w_k, 0.0))
        v = sign * np.cumsum(p.w_h) - w_minus
        assert np.all(v >= MIN_SLOPE * (1 - 1e-9) - 1e-12)
        assert not_invertible_reason(structure, p) == ""


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_bounded_output(size):
    structure = FAMILY.make_structure(0.025, size)
    u = _sine_steps()
    rng = np.random.default_rng(11)
    for _ in range(40):
        p = FAMILY.random_params(structure, rng)
        y, _ = FAMILY.simulate(structure, p, u)
        assert np.all(np.isfinite(y))
        assert np.max(np.abs(y)) <= np.sum(np.abs(p.w_s)) * (np.sum(np.abs(p.w_h)) + np.sum(np.abs(p.w_k)) + abs(p.b)) * (1 + 1e-9) + 1e-12
