"""Helpers shared by the model families' tests (fixtures: visible without an import)."""

from __future__ import annotations

import numpy as np
import pytest


def _drive(run, x0, signal, off=None):
    """Run ``run`` sample by sample: a compiled block (``off`` = its slice's offset inside a
    larger loop state whose neighbours must stay untouched) or a step function ``run(x, v)``.
    Returns the outputs and the state after every sample."""
    x, out, states = np.asarray(x0, float), [], []
    for v in signal:
        if off is None:
            y, x = run(x, v)
        else:
            big = np.full(off + x.size + 2, 7.0)
            big[off:off + x.size] = x
            xn = big.copy()
            y = run.step(run.body, big, xn, off, v)
            assert np.all(xn[:off] == 7.0) and np.all(xn[off + x.size:] == 7.0)
            x = xn[off:off + x.size]
        out.append(y)
        states.append(x)
    return np.array(out), np.array(states)


@pytest.fixture
def drive():
    """:func:`_drive`: a loop block or a step function run sample by sample."""
    return _drive


@pytest.fixture
def bounded_input() -> np.ndarray:
    """|u| <= 1 at 40 Hz: a 0.9 sine sweep 0.05 -> 1 Hz, steps to 1, -1 and 0.3 (reversals)."""
    n, dt = 2000, 0.025
    t = np.arange(n) * dt
    u = 0.9 * np.sin(2 * np.pi * np.cumsum(0.05 * 20.0 ** (t / t[-1])) * dt)
    u[750:850], u[850:950], u[950:1050] = 1.0, -1.0, 0.3
    return u


@pytest.fixture
def random_draws():
    """``draws(family, structure, n=50, seed=3)``: seeded parameter sets from the family's
    ``random_params``."""
    def draws(family, structure, n: int = 50, seed: int = 3):
        rng = np.random.default_rng(seed)
        return [family.random_params(structure, rng) for _ in range(n)]
    return draws


@pytest.fixture
def random_runs(random_draws, bounded_input):
    """``runs(family, structure, n=40, seed=11)``: (params, output) of seeded draws run on the
    bounded input; a non-finite output fails here."""
    def runs(family, structure, n: int = 40, seed: int = 11):
        out = []
        for p in random_draws(family, structure, n, seed):
            y, _ = family.simulate(structure, p, bounded_input)
            assert np.all(np.isfinite(y))
            out.append((p, y))
        return out
    return runs
