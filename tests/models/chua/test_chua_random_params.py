"""random_params of the chua family: accepted by Params, inside the stated domain, seeded."""

import numpy as np
import pytest

from hystkit.models import get_family

FAMILY = get_family("chua")


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
        for name in ("k0", "k_inf", "y_s"):
            v = getattr(p, name)
            assert np.all((v >= 1e-2 * (1 - 1e-12)) & (v <= 1e2 * (1 + 1e-12)))
        assert np.all((p.g >= 1e-3 * (1 - 1e-12)) & (p.g <= 100 / structure.dt * (1 + 1e-12)))
        assert np.all((p.v_g >= 1e-3 * (1 - 1e-12)) & (p.v_g <= 1e3 * (1 + 1e-12)))
        assert np.all((p.delta >= 0) & (p.delta <= 1))


def test_random_params_bounded_output():
    structure = FAMILY.make_structure(0.025, 2 * FAMILY.default_size)
    u = _sine_steps()
    rng = np.random.default_rng(11)
    for _ in range(40):
        p = FAMILY.random_params(structure, rng)
        y, _ = FAMILY.simulate(structure, p, u)
        assert np.all(np.isfinite(y))
        assert np.max(np.abs(y)) <= np.sum((np.max(np.abs(u)) + p.delta) / np.minimum(p.k0, p.k_inf)) * (1 + 1e-9)
