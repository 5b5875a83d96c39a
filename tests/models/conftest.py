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
