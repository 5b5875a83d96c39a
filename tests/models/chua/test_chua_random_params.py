"""random_params of the chua family: accepted by Params, inside the stated domain."""

import numpy as np
import pytest

from hystkit.models import get_family

FAMILY = get_family("chua")


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain(size, random_draws):
    structure = FAMILY.make_structure(0.025, size)
    for p in random_draws(FAMILY, structure):
        for name in ("k0", "k_inf", "y_s"):
            v = getattr(p, name)
            assert np.all((v >= 1e-2 * (1 - 1e-12)) & (v <= 1e2 * (1 + 1e-12)))
        assert np.all((p.g >= 1e-3 * (1 - 1e-12)) & (p.g <= 100 / structure.dt * (1 + 1e-12)))
        assert np.all((p.v_g >= 1e-3 * (1 - 1e-12)) & (p.v_g <= 1e3 * (1 + 1e-12)))
        assert np.all((p.delta >= 0) & (p.delta <= 1))


def test_random_params_bounded_output(bounded_input, random_runs):
    structure = FAMILY.make_structure(0.025, 2 * FAMILY.default_size)
    u = bounded_input
    for p, y in random_runs(FAMILY, structure):
        assert np.max(np.abs(y)) <= np.sum((np.max(np.abs(u)) + p.delta) / np.minimum(p.k0, p.k_inf)) * (1 + 1e-9)
