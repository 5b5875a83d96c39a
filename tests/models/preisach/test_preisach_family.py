"""The staircase families (classical and generalised Preisach) behind the family protocol:
packed loop state, rest states, compiled loop blocks, rate independence, branch linearisation.

Both families share ``StaircaseFamily`` (``models/preisach/family.py``), so both are checked
here."""

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.models import gpreisach as G
from hystkit.models import preisach as P

L = 8
CAP = 2 * L + 4  # small: the blocks run into the full staircase


def _masses(seed: int, diagonal: bool = True) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.tril(rng.uniform(0.05, 1.0, (L - 1, L - 1)), 0 if diagonal else -1)


CASES = {
    "preisach": (P.FAMILY, P.PreisachStructure(levels=L, capacity=CAP),
                 P.PreisachParams.from_masses(_masses(0), offset=0.2)),
    "gpreisach": (G.FAMILY, G.GPreisachStructure(levels=L, capacity=CAP),
                  G.GPreisachParams(everett_minus=P.everett_from_masses(_masses(1, False)),
                                    everett_plus=P.everett_from_masses(1.2 * _masses(1, False)),
                                    nu=[0.5, 0.1, 0.8], offset=0.1)),
}


def _walk(n: int, seed: int) -> np.ndarray:
    """Random reversals of all sizes, partly beyond [-1, 1], then a decaying zigzag (a new
    nested extremum every sample) that fills the staircase."""
    rng = np.random.default_rng(seed)
    walk = 1.2 * np.sin(np.cumsum(rng.standard_normal(n)) * 0.4)
    zigzag = 0.1 + 0.8 * (-1.0) ** np.arange(2 * CAP) * 0.93 ** np.arange(2 * CAP)
    return np.concatenate([walk, zigzag, walk[::-1]])


@pytest.mark.parametrize("inverse", [False, True])
@pytest.mark.parametrize("name", CASES)
def test_block_equals_step_from_a_non_rest_state(name, inverse):
    family, structure, params = CASES[name]
    u = _walk(150, 1)
    x = family.simulate(structure, params, _walk(100, 2))[1]  # deep in a history
    signal = family.simulate(structure, params, u, x)[0] if inverse else u
    block = family.block(structure, params, inverse)
    run = family.invert_step if inverse else family.step
    assert block.n_state == CAP + 1
    off = 3
    big = np.zeros(off + block.n_state + 2)
    big[off:off + block.n_state] = x
    longest = 0
    for v in signal:
        xn = np.full_like(big, np.nan)  # the block writes its whole slice
        out = block.step(block.body, big, xn, off, v)
        ref, x = run(structure, params, x, v)
        assert out == pytest.approx(ref, abs=1e-12)
        assert_allclose(xn[off:off + block.n_state], x, rtol=0, atol=1e-12)
        assert np.all(np.isnan(xn[:off])) and np.all(np.isnan(xn[off + block.n_state:]))
        big[off:off + block.n_state] = xn[off:off + block.n_state]
        longest = max(longest, int(x[0]))
    assert longest >= CAP - 3  # the zigzag reached the full staircase


@pytest.mark.parametrize("name", CASES)
def test_full_capacity_forgets_inner_loops_and_stays_valid(name):
    family, structure, params = CASES[name]
    block = family.block(structure, params)
    x = family.rest_state(structure, params, 0.0)
    for v in 0.9 * (-1.0) ** np.arange(5 * CAP) * 0.97 ** np.arange(5 * CAP):
        xn = np.empty_like(x)
        block.step(block.body, x, xn, 0, v)
        x = xn
        staircase = P.unpack_state(x, CAP)  # length inside 1..capacity
        P.check_state(staircase, CAP)  # still alternating, nested
        assert staircase.size <= CAP - 1 and staircase[-1] == pytest.approx(v)
        assert np.all(x[1 + staircase.size:] == 0.0)


@pytest.mark.parametrize("inverse", [False, True])
@pytest.mark.parametrize("name", CASES)
def test_rest_state_is_the_default_start_and_a_fixed_point(name, inverse):
    family, structure, params = CASES[name]
    run = family.invert if inverse else family.simulate
    run_step = family.invert_step if inverse else family.step
    signal = 0.3 + 0.5 * np.sin(np.linspace(0, 9, 200))
    if inverse:
        signal = family.simulate(structure, params, signal)[0]
    for value in (signal[0], -0.7, 1.3):
        x = family.rest_state(structure, params, value, inverse)
        out, x_next = run_step(structure, params, x, value)
        assert_array_equal(x_next, x)
        # readable step vs compiled run: summation order only
        assert out == pytest.approx(run(structure, params, np.array([value]))[0][0], abs=1e-12)
    x = family.rest_state(structure, params, signal[0], inverse)
    out, x_end = run(structure, params, signal)
    out_rest, x_end_rest = run(structure, params, signal, x)
    assert_array_equal(out_rest, out)
    assert_array_equal(x_end_rest, x_end)


@pytest.mark.parametrize("name", CASES)
def test_at_another_sample_time_is_the_same_model(name):
    family, structure, params = CASES[name]
    structure = dataclasses.replace(structure, capacity=1024)  # no forgetting in this test
    fast = family.at(structure, 0.001)
    assert fast == dataclasses.replace(structure, dt=0.001)
    u = _walk(300, 3)[:300]
    y, x_end = family.simulate(structure, params, u)
    assert_array_equal(family.simulate(fast, params, u)[0], y)
    # the same input path sampled 5 times as often (linear between the samples) gives the
    # same output at the common instants: rate independence
    k = 5
    fine = np.interp(np.arange((u.size - 1) * k + 1) / k, np.arange(u.size), u)
    y_fine, x_fine = family.simulate(fast, params, fine)
    assert_allclose(y_fine[::k], y, rtol=0, atol=1e-12)
    assert_array_equal(x_fine, x_end)


@pytest.mark.parametrize("name", CASES)
def test_linearise_is_the_one_sided_branch_slope(name):
    family, structure, params = CASES[name]
    x = family.simulate(structure, params, _walk(100, 4))[1]
    last = P.unpack_state(x, CAP)[-1]
    h = 1e-7
    for u, direction in ((last + 0.05, 1.0), (last - 0.05, -1.0), (last, None)):
        a, b, c, d = family.linearise(structure, params, x, u)
        if direction is None:  # at rest: onwards along the last segment
            staircase = P.unpack_state(x, CAP)
            direction = 1.0 if staircase[-1] > staircase[-2] else -1.0
        y_u, x_u = family.step(structure, params, x, u)
        y_h = family.step(structure, params, x, u + direction * h)[0]
        # the stored extrema hold (eigenvalue 1), the present input's entry follows u
        k = int(x_u[0])
        n = CAP + 1
        assert a.shape == (n, n) and b.shape == c.shape == (n,) and not c.any()
        assert_array_equal(a, np.diag(np.r_[0.0, np.ones(k - 1), np.zeros(n - k)]))
        assert_array_equal(b, np.eye(n)[k])
        assert np.max(np.abs(np.linalg.eigvals(a))) == 1.0
        assert np.isfinite(d) and d == pytest.approx((y_h - y_u) / (direction * h), rel=1e-4)
        assert d > 0  # non-negative weights: rising branches
        # the inverse's slope at the output this input gives is the reciprocal
        d_inv = family.linearise(structure, params, x, y_u, inverse=True)[3]
        assert d_inv == pytest.approx(1.0 / d, rel=1e-4)


@pytest.mark.parametrize("name", CASES)
def test_at_rest_the_two_sided_jacobian_is_degenerate_and_linearise_is_not(name):
    # why linearise is one-sided: a reversal pushes an entry, the count jumps
    family, structure, params = CASES[name]
    x = family.rest_state(structure, params, 0.2)
    h = 1e-6
    up, down = (family.step(structure, params, x, 0.2 + s)[1] for s in (h, -h))
    assert abs(up[0] - down[0]) == 1.0
    assert np.isfinite(family.linearise(structure, params, x, 0.2)[3])


def test_packed_state_round_trip_and_checks():
    staircase = np.array([-1.0, 0.5, -0.2, 0.3])
    packed = P.pack_state(staircase, CAP)
    assert packed.shape == (CAP + 1,) and packed[0] == 4.0 and not packed[5:].any()
    assert_array_equal(P.unpack_state(packed, CAP), staircase)
    packed[0] = 4.0 + 1e-9  # a float count is rounded, not truncated
    assert_array_equal(P.unpack_state(packed, CAP), staircase)
    with pytest.raises(ValueError, match="shape"):
        P.unpack_state(packed[:-1], CAP)
    with pytest.raises(ValueError, match="length"):
        P.unpack_state(np.r_[CAP + 1.0, np.zeros(CAP)], CAP)
    with pytest.raises(ValueError, match="capacity"):
        P.pack_state(np.zeros(CAP + 1), CAP)
