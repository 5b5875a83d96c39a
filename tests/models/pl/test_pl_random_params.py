"""random_params of the pl family: accepted by Params, inside the stated domain."""

import numpy as np
import pytest

from hystkit.models import get_family

FAMILY = get_family("pl")


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain(size, random_draws):
    structure = FAMILY.make_structure(0.025, size)
    for p in random_draws(FAMILY, structure):
        assert 1e-6 * (1 - 1e-12) <= p.i_t <= 1e4 * (1 + 1e-12)
        assert 1e-3 * (1 - 1e-12) <= p.v_t <= 2 * (1 + 1e-12)
        assert np.all(p.a >= 0.05) and np.isclose(p.a.sum(), structure.n_basis)
        assert np.all(np.abs(p.w) <= 100) and abs(p.v_b) <= 100


def test_random_params_bounded_output(bounded_input, random_runs):
    structure = FAMILY.make_structure(0.025, 2 * FAMILY.default_size)
    u = bounded_input
    for p, y in random_runs(FAMILY, structure):
        assert np.max(np.abs(y)) <= (np.sum(np.abs(p.w)) * np.max(np.abs(u)) + abs(p.v_b)) / np.min(p.a) * (1 + 1e-9)
