"""random_params of the mpl-poly family: accepted by Params, inside the stated domain."""

import numpy as np
import pytest

from hystkit.models import get_family

FAMILY = get_family("mpl-poly")


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_in_domain(size, random_draws):
    structure = FAMILY.make_structure(0.025, size)
    for p in random_draws(FAMILY, structure):
        assert np.all(np.abs(p.f[:, :3]) <= 5)
        assert np.all((p.f[:, 3] >= 0.1 * (1 - 1e-12)) & (p.f[:, 3] <= 100 * (1 + 1e-12)))
        assert np.all(np.abs(p.g) <= 2) and np.all(np.abs(p.w) <= 2) and abs(p.v_b) <= 1


def test_random_params_bounded_output(bounded_input, random_runs):
    structure = FAMILY.make_structure(0.025, 2 * FAMILY.default_size)
    u = bounded_input
    for p, y in random_runs(FAMILY, structure):
        assert np.max(np.abs(y)) <= _poly_bound(structure, p, u)


def _poly_bound(structure, p, u):
    """|u_k| <= max|e| + max|v*_k| (the limited cell's step is monotone, its rest points
    bracket it), then |z| <= Z and |y| <= sum |g_j| max(1, Z)^j."""
    from hystkit.models.mpl_poly import model as mpl_poly

    reach = np.array([np.max(np.abs(v)) for v in mpl_poly.equilibria(structure, p)])
    z = abs(p.w[0]) * np.max(np.abs(u)) + np.abs(p.w[1:]) @ (np.max(np.abs(u)) + reach)
    z = max(z + abs(p.v_b), 1.0)
    return float(np.sum(np.abs(p.g) * z ** np.arange(4))) * (1 + 1e-9)
