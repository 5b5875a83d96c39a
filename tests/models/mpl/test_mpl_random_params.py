"""random_params of the mpl family: accepted by Params, inside the stated domain."""

import numpy as np
import pytest

from hystkit.models import get_family

FAMILY = get_family("mpl")


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain(size, random_draws):
    structure = FAMILY.make_structure(0.025, size)
    for p in random_draws(FAMILY, structure):
        g = 2 * p.i_s / p.v_t
        assert np.all((g >= 1e-4 * (1 - 1e-12)) & (g <= structure.slope_cap / structure.dt * (1 + 1e-12)))
        assert np.all((p.v_t >= 1e-3 * (1 - 1e-12)) & (p.v_t <= 1e3 * (1 + 1e-12)))
        assert np.all(np.abs(p.w) <= 100) and abs(p.v_b) <= 100


def test_random_params_bounded_output(bounded_input, random_runs):
    structure = FAMILY.make_structure(0.025, 2 * FAMILY.default_size)
    u = bounded_input
    for p, y in random_runs(FAMILY, structure):
        assert np.max(np.abs(y)) <= np.sum(np.abs(p.w)) * np.max(np.abs(u)) + abs(p.v_b) + 1e-9
