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


def _check_bounded_run(family, structure, params, u, bound_of, *, rel, diverged=("sample",)):
    """The fuzz tests' checks of one accepted parameter set (issue 10): the run is finite and
    within ``bound_of(max|u|)``; the readable step and the loop's compiled block follow it for
    three samples; the inverse is finite or raises FitDivergedError naming one of `diverged`."""
    from hystkit.errors import FitDivergedError

    y, x_end = family.simulate(structure, params, u)
    assert np.all(np.isfinite(y)) and np.all(np.isfinite(x_end))
    bound = bound_of(np.max(np.abs(u)))
    # subnormal results are rounded to 5e-324 absolute, not relative
    assert np.max(np.abs(y)) <= bound * (1 + rel) + 1e-300
    # rounding is relative to the terms summed (up to the bound), not to a cancelled y
    blk = family.block(structure, params)
    x = x_blk = family.rest_state(structure, params, u[0])
    for k in range(3):
        y_k, x = family.step(structure, params, x, u[k])
        x_next = x_blk.copy()
        y_blk = blk.step(blk.body, x_blk, x_next, 0, u[k])
        x_blk = x_next
        assert y_k == pytest.approx(y[k], rel=rel, abs=1e-12 * bound)
        assert y_blk == pytest.approx(y[k], rel=rel, abs=1e-12 * bound)
    try:
        u_hat, x_end = family.invert(structure, params, y)
    except FitDivergedError as exc:
        assert any(fragment in str(exc) for fragment in diverged), str(exc)
        return
    assert np.all(np.isfinite(u_hat)) and np.all(np.isfinite(x_end))


@pytest.fixture(scope="session")  # session scope: usable inside hypothesis tests
def check_bounded_run():
    return _check_bounded_run
