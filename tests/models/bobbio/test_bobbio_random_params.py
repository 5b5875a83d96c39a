"""random_params of the bobbio family: accepted by Params, inside the stated domain,
and bounded by sum c_k max|u| + |b| (every spring force is a play of u)."""

import numpy as np
import pytest

from hystkit.models import get_family

FAMILY = get_family("bobbio")


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain(size, random_draws):
    structure = FAMILY.make_structure(0.025, size)
    for p in random_draws(FAMILY, structure):
        assert np.all(p.compliance >= 0)
        assert 0.1 * (1 - 1e-9) <= p.compliance.sum() <= 10 * (1 + 1e-9)
        radius = p.friction.sum()
        assert 0.1 * (1 - 1e-9) <= radius <= 1.5 * (1 + 1e-9)
        assert np.all(p.friction >= 0.1 * radius / (size - 1) * (1 - 1e-9))
        assert abs(p.offset) <= 1


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_bounded_output(size, bounded_input, random_runs):
    structure = FAMILY.make_structure(0.025, size)
    u = bounded_input
    for p, y in random_runs(FAMILY, structure):
        assert np.max(np.abs(y)) <= np.sum(p.compliance) * np.max(np.abs(u)) + abs(p.offset) * (1 + 1e-9) + 1e-12
