"""random_params of the mpl-poly family: accepted by Params, inside the stated domain, seeded."""

import numpy as np
import pytest

from hystkit.models import get_family

FAMILY = get_family("mpl-poly")


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
    rng = np.random.default_rng(3)
    for _ in range(50):
        p = FAMILY.random_params(structure, rng)
        assert FAMILY.Params.from_dict(p.to_dict()) == p  # the constructor accepts it
        assert np.all(np.abs(p.f[:, :3]) <= 5)
        assert np.all((p.f[:, 3] >= 0.1 * (1 - 1e-12)) & (p.f[:, 3] <= 100 * (1 + 1e-12)))
        assert np.all(np.abs(p.g) <= 2) and np.all(np.abs(p.w) <= 2) and abs(p.v_b) <= 1


def test_random_params_bounded_output():
    structure = FAMILY.make_structure(0.025, 2 * FAMILY.default_size)
    u = _sine_steps()
    rng = np.random.default_rng(11)
    for _ in range(40):
        p = FAMILY.random_params(structure, rng)
        y, _ = FAMILY.simulate(structure, p, u)
        assert np.all(np.isfinite(y))
        assert np.max(np.abs(y)) <= _poly_bound(structure, p, u)


def _poly_bound(structure, p, u):
    """|u_k| <= max|e| + max|v*_k| (the limited cell's step is monotone, its rest points
    bracket it), then |z| <= Z and |y| <= sum |g_j| max(1, Z)^j."""
    from hystkit.models.mpl_poly import model as mpl_poly

    reach = np.array([np.max(np.abs(v)) for v in mpl_poly.equilibria(structure, p)])
    z = abs(p.w[0]) * np.max(np.abs(u)) + np.abs(p.w[1:]) @ (np.max(np.abs(u)) + reach)
    z = max(z + abs(p.v_b), 1.0)
    return float(np.sum(np.abs(p.g) * z ** np.arange(4))) * (1 + 1e-9)
