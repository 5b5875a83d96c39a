"""random_params of the bobbio family: accepted by Params, inside the stated domain, seeded,
and bounded by sum c_k max|u| + |b| (every spring force is a play of u)."""

import numpy as np
import pytest

from hystkit.models import get_family

FAMILY = get_family("bobbio")


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
        assert np.all(p.compliance >= 0)
        assert 0.1 * (1 - 1e-9) <= p.compliance.sum() <= 10 * (1 + 1e-9)
        radius = p.friction.sum()
        assert 0.1 * (1 - 1e-9) <= radius <= 1.5 * (1 + 1e-9)
        assert np.all(p.friction >= 0.1 * radius / (size - 1) * (1 - 1e-9))
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
        assert np.max(np.abs(y)) <= np.sum(p.compliance) * np.max(np.abs(u)) + abs(p.offset) * (1 + 1e-9) + 1e-12
