"""PL kernels with the per-cell constants out of the sample loop (issue 29, item 2): the run
follows the per-sample formula it replaced to rounding, and the blocks (which recompute the
constants per call) advance the state bit for bit as the run does."""

import numpy as np
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.models import get_family, pl
from hystkit.models.pl import kernels

DT = 0.025
# power 5 with a large I_T: knees well inside the thresholds, crossed on the noise
STRUCTURE = pl.PlStructure(n_cells=2, power=5.0, n_basis=3, dt=DT)
PARAMS = pl.PlParams(i_t=100.0, v_t=0.3, w=[0.6, 0.5, -0.3], v_b=0.05, a=[0.8, 1.0, 1.2])


def _input(n: int = 2000) -> np.ndarray:
    t = np.arange(n) * DT
    return np.sin(0.5 * t) + 0.3 * np.random.default_rng(5).standard_normal(n)


def _per_sample_states(u, x0, i_t, thr, knee, power, g_lin, dt):
    """The states with the current computed in full at every sample (the former kernel)."""
    x = x0.copy()
    for u_n in u:
        for k in range(x.size):
            v = u_n - x[k]
            a, s = abs(v), (1.0 if v >= 0 else -1.0)
            scale = i_t / (power - 1.0)
            f = (s * scale * (a / thr[k]) ** power if a <= knee[k] else
                 s * (scale * (knee[k] / thr[k]) ** power + g_lin * (a - knee[k])))
            x[k] += f * dt
    return x


def test_hoisted_run_follows_the_per_sample_formula_to_rounding():
    u = _input()
    args = pl.kernel_args(STRUCTURE, PARAMS)
    knee = args[2]
    x0 = np.zeros(2)
    _, x_end = kernels.states(u, x0, *args)
    v = u[:, None] - kernels.states(u, x0, *args)[0]
    assert np.any(np.abs(v) > knee) and np.any(np.abs(v) <= knee)  # both branches taken
    # tests/models/pl/test_pl.py's tolerance for the state against the readable steps
    assert_allclose(x_end, _per_sample_states(u, x0, *args), rtol=0, atol=1e-14)


def test_blocks_follow_the_run_bit_for_bit():
    u = _input()
    family = get_family("pl")
    y, x_end = pl.simulate(STRUCTURE, PARAMS, u)
    block = family.block(STRUCTURE, PARAMS, False)
    x = np.full(block.n_state, u[0])
    xn = np.empty_like(x)
    out = np.empty(u.size)
    for n, u_n in enumerate(u):
        out[n] = block.step(block.body, x, xn, 0, u_n)
        x, xn = xn, x
    assert_array_equal(out, y)
    assert_array_equal(x, x_end)
