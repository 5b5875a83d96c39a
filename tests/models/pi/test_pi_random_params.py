"""random_params of the pi family: accepted by Params, inside the stated domain,
and bounded by sum |w_S| (sum |w_H| + sum |w_K| + |b|) for |u| <= 1."""

import numpy as np
import pytest

from hystkit.models import get_family
from hystkit.models.pi import MIN_SLOPE, inverse_superposition, not_invertible_reason

FAMILY = get_family("pi")


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain(size, random_draws):
    structure = FAMILY.make_structure(0.025, size)
    for p in random_draws(FAMILY, structure):
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
def test_random_params_bounded_output(size, random_runs):
    structure = FAMILY.make_structure(0.025, size)
    for p, y in random_runs(FAMILY, structure):
        assert np.max(np.abs(y)) <= np.sum(np.abs(p.w_s)) * (np.sum(np.abs(p.w_h)) + np.sum(np.abs(p.w_k)) + abs(p.b)) * (1 + 1e-9) + 1e-12
