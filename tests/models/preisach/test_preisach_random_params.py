"""random_params of the preisach family: accepted by Params, inside the stated domain,
and bounded by the total |mass| plus |y_0| for |u| <= 1."""

import numpy as np
import pytest

from hystkit.models import get_family
from hystkit.models.preisach import masses_from_everett

FAMILY = get_family("preisach")


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain(size, random_draws):
    structure = FAMILY.make_structure(0.025, size)
    for p in random_draws(FAMILY, structure):
        masses = masses_from_everett(p.everett)
        off = ~np.eye(masses.shape[0], dtype=bool) & np.tri(masses.shape[0], dtype=bool)
        assert np.all(np.diag(masses) >= 0)
        assert np.all(masses[off] >= -1e-15) or np.all(masses[off] <= 1e-15)  # one orientation
        assert 0.1 * (1 - 1e-9) <= np.sum(np.abs(masses)) <= 10 * (1 + 1e-9)
        assert abs(p.offset) <= 1


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_bounded_output(size, random_runs):
    structure = FAMILY.make_structure(0.025, size)
    for p, y in random_runs(FAMILY, structure):
        assert np.max(np.abs(y)) <= np.sum(np.abs(masses_from_everett(p.everett))) + abs(p.offset) * (1 + 1e-9) + 1e-12
