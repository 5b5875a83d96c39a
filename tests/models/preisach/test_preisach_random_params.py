"""random_params of the preisach family: accepted by Params, inside the stated domain, seeded,
and bounded by the total |mass| plus |y_0| for |u| <= 1."""

import numpy as np
import pytest

from hystkit.models import get_family
from hystkit.models.preisach import masses_from_everett

FAMILY = get_family("preisach")


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
        masses = masses_from_everett(p.everett)
        off = ~np.eye(masses.shape[0], dtype=bool) & np.tri(masses.shape[0], dtype=bool)
        assert np.all(np.diag(masses) >= 0)
        assert np.all(masses[off] >= -1e-15) or np.all(masses[off] <= 1e-15)  # one orientation
        assert 0.1 * (1 - 1e-9) <= np.sum(np.abs(masses)) <= 10 * (1 + 1e-9)
        assert abs(p.offset) <= 1


@pytest.mark.parametrize("size", [FAMILY.default_size, 2 * FAMILY.default_size])
def test_random_params_bounded_output(size):
    structure = FAMILY.make_structure(0.025, size)
    u = _sine_steps()
    rng = np.random.default_rng(11)
    for _ in range(40):
        p = FAMILY.random_params(structure, rng)
        y, _ = FAMILY.simulate(structure, p, u)
        assert np.all(np.isfinite(y))
        assert np.max(np.abs(y)) <= np.sum(np.abs(masses_from_everett(p.everett))) + abs(p.offset) * (1 + 1e-9) + 1e-12
