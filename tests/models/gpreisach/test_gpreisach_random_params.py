"""random_params of the gpreisach family: accepted by Params, inside the stated domain,
and bounded by max(total |mass| of mu_-, of mu_+) + int nu + |y_0| for |u| <= 1."""

import numpy as np
import pytest

from hystkit.models import get_family
from hystkit.models.preisach import masses_from_everett

FAMILY = get_family("gpreisach")


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain(size, random_draws):
    structure = FAMILY.make_structure(0.025, size)
    for p in random_draws(FAMILY, structure):
        tables = [masses_from_everett(t) for t in (p.everett_minus, p.everett_plus)]
        off = ~np.eye(tables[0].shape[0], dtype=bool) & np.tri(tables[0].shape[0], dtype=bool)
        signs = np.concatenate([t[off] for t in tables])
        assert np.all(signs >= -1e-15) or np.all(signs <= 1e-15)  # one orientation for both
        for t in tables:
            assert np.allclose(np.diag(t), 0.0, atol=1e-15)
            assert 0.1 * (1 - 1e-9) <= np.sum(np.abs(t)) <= 10 * (1 + 1e-9)
        assert np.all(p.nu >= 0)
        assert 0.01 * (1 - 1e-9) <= 2 * np.sum(p.nu) / p.nu.size <= 10 * (1 + 1e-9)
        assert abs(p.offset) <= 1


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_bounded_output(size, random_runs):
    structure = FAMILY.make_structure(0.025, size)
    for p, y in random_runs(FAMILY, structure):
        assert np.max(np.abs(y)) <= (max(np.sum(np.abs(masses_from_everett(t))) for t in (p.everett_minus, p.everett_plus))
                + 2 * np.sum(p.nu) / p.nu.size + abs(p.offset)) * (1 + 1e-9) + 1e-12
