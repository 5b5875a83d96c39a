"""Classical Preisach model (sec. 2.1.1, eq. 9.4-9.13): staircase memory, Everett function,
the properties of the representation theorem, FORC and least-squares identification, inverse."""

import json
from dataclasses import asdict
from itertools import pairwise

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.compensation import (
    compensator_from_dict,
    compensator_to_dict,
    evaluate,
    fit_compensator,
)
from hystkit.errors import FitDivergedError
from hystkit.models import get_family
from hystkit.models import preisach as P
from hystkit.models.preisach import everett_from_forcs, fit_preisach
from hystkit.sensors import simulate_experiment

L = 9
STRUCT = P.PreisachStructure(levels=L, capacity=2 * L + 4)  # small: exercises the pruning


def _masses(seed: int, low: float = 0.0, sparsity: float = 0.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    m = np.tril(rng.uniform(low, 1.0, (L - 1, L - 1)))
    m[rng.uniform(size=m.shape) < sparsity] = 0.0
    return m


PARAMS = P.PreisachParams.from_masses(_masses(0, low=0.05), offset=0.2)


def _walk(n: int, seed: int, amplitude: float = 1.2) -> np.ndarray:
    """Random input with many reversals of all sizes, partly beyond the range [-1, 1]."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.025
    return amplitude * np.sin(np.cumsum(rng.standard_normal(n)) * 0.4) * np.exp(-t / 60)


def _path(*points: float, n: int = 7) -> np.ndarray:
    """Piecewise-linear input through ``points``, ``n`` samples per leg (no extra extrema)."""
    legs = [np.linspace(a, b, n)[1:] for a, b in pairwise(points)]
    return np.concatenate([[points[0]], *legs])


def test_kernel_matches_readable_reference():
    u = _walk(3000, 1)
    y, x_end = P.simulate(STRUCT, PARAMS, u)
    y_ref, x_ref = P.simulate_reference(STRUCT, PARAMS, u)
    # same staircase rule; the kernel sums the segment terms incrementally, the reference
    # afresh each sample, so only the summation order differs (a few ulps of the output)
    assert_allclose(y, y_ref, rtol=0, atol=1e-12)
    assert_array_equal(x_end, x_ref)


def test_everett_nodes_are_cell_sums_and_interpolant_vanishes_on_the_diagonal():
    m = _masses(3)
    e = P.everett_from_masses(m)
    for a in range(L):
        for b in range(a):
            inside = sum(m[i, j] for i in range(b, a) for j in range(b, i + 1))  # eq. 9.6
            assert e[a, b] == pytest.approx(inside, rel=1e-13)
    assert_allclose(P.masses_from_everett(e), m, atol=1e-13)
    params = P.PreisachParams(e)
    h = P.grid(L)
    ia, ib = np.tril_indices(L, -1)
    assert_allclose(P.everett(params, h[ia], h[ib]), e[ia, ib], rtol=0, atol=1e-14)
    d = np.linspace(-1, 1, 101)
    # F(a, a) = 0: the two off-diagonal corner terms cancel up to the rounding of products
    assert_allclose(P.everett(params, d, d), 0.0, rtol=0, atol=1e-15)


def test_uniform_density_follows_the_closed_form_branches():
    # mu = c on T: F(a, b) = c (a - b)^2 / 2 (eq. 9.6), F(1, -1) = 2c. From negative
    # saturation the ascending branch is -2c + c (u + 1)^2, the descending one from +1 is
    # 2c - c (1 - u)^2 (eq. 9.13). Exact at the grid levels, where the interpolant has the
    # node values; between them the branch is the chord of the parabola.
    c = 0.7
    h = P.grid(L)
    e = np.tril(c * (h[:, None] - h[None, :]) ** 2 / 2, -1)
    params = P.PreisachParams(e)
    y_up, _ = P.simulate(STRUCT, params, h, x0=[-1.0])
    assert_allclose(y_up, -2 * c + c * (h + 1) ** 2, rtol=0, atol=1e-14)
    y_down, _ = P.simulate(STRUCT, params, h[::-1], x0=[-1.0, 1.0])
    assert_allclose(y_down, 2 * c - c * (1 - h[::-1]) ** 2, rtol=0, atol=1e-14)
    mid = 0.5 * (h[2] + h[3])
    y_mid, _ = P.simulate(STRUCT, params, np.array([mid]), x0=[-1.0])
    chord = -2 * c + c * 0.5 * ((h[2] + 1) ** 2 + (h[3] + 1) ** 2)
    assert y_mid[0] == pytest.approx(chord, abs=1e-14)


def test_output_is_eq_9_13_over_the_staircase():
    # rise to M1, fall to m1, rise to M2 < M1: y = -F0 + 2[F(M1, -1) - F(M1, m1)] + 2 F(M2, m1)
    m0, M1, m1, M2 = -1.0, 0.8, -0.5, 0.3
    y, x = P.simulate(STRUCT, PARAMS, np.array([M1, m1, M2]), x0=[-1.0])

    def F(a: float, b: float) -> float:
        return float(P.everett(PARAMS, a, b))

    f0 = PARAMS.everett[-1, 0]
    assert_array_equal(x, [-1.0, M1, m1, M2])
    expected = -f0 + 2 * (F(M1, m0) - F(M1, m1)) + 2 * F(M2, m1) + PARAMS.offset
    assert y[-1] == pytest.approx(expected, abs=1e-14)
    # falling to u = 0.1 (eq. 9.13 as printed): ... + 2 [F(M2, m1) - F(M2, u)]
    y, _ = P.simulate(STRUCT, PARAMS, np.array([0.1]), x0=x)
    expected = -f0 + 2 * (F(M1, m0) - F(M1, m1)) + 2 * (F(M2, m1) - F(M2, 0.1)) + PARAMS.offset
    assert y[0] == pytest.approx(expected, abs=1e-14)


def test_saturation_states_and_the_straight_line_beyond():
    f0 = PARAMS.everett[-1, 0]
    y, x = P.simulate(STRUCT, PARAMS, np.array([-1.0, 1.0, 1.5, -2.0]))
    assert_allclose(y, [-f0 + 0.2, f0 + 0.2, f0 * 1.5 + 0.2, -2 * f0 + 0.2], atol=1e-14)
    assert_array_equal(x, [-1.0])  # negative saturation, everything wiped


def test_default_state_is_demagnetised():
    # The demagnetised staircase (alpha + beta = 0 at each step's midpoint) is symmetric under
    # (alpha, beta) -> (-beta, -alpha); so is a uniform density and its Everett grid. The
    # output at u = 0 is odd under that map, hence 0 (up to rounding).
    h = P.grid(L)
    params = P.PreisachParams(np.tril((h[:, None] - h[None, :]) ** 2 / 2, -1))
    y, x = P.simulate(STRUCT, params, np.zeros(1))
    assert abs(y[0]) < 1e-14
    assert_array_equal(x, P.demagnetised_state(L - 1))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), top=st.floats(0.3, 1.0))
def test_wiping_out(seed, top):
    """After a larger extremum the memory of smaller ones is erased: two different histories
    below ``top`` give identical states and outputs once ``top`` is reached."""
    rng = np.random.default_rng(seed)
    hist_a = rng.uniform(-1, top - 0.01, 30)
    hist_b = rng.uniform(-1, top - 0.01, 17)
    after = np.r_[top, _walk(200, seed, amplitude=top)]
    y_a, x_a = P.simulate(STRUCT, PARAMS, np.r_[hist_a, after], x0=[-1.0])
    y_b, x_b = P.simulate(STRUCT, PARAMS, np.r_[hist_b, after], x0=[-1.0])
    assert_allclose(y_a[hist_a.size:], y_b[hist_b.size:], rtol=0, atol=1e-13)
    assert_array_equal(x_a, x_b)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), lo=st.floats(-0.9, 0.3), width=st.floats(0.05, 0.6))
def test_minor_loops_between_the_same_extrema_are_congruent(seed, lo, width):
    """Mayergoyz's congruency: after different histories, the loops between u1 and u2 differ
    only by a constant shift (the output increments depend on u1, u2 and u only)."""
    u1, u2 = lo, min(lo + width, 1.0)
    rng = np.random.default_rng(seed)
    loop = _path(u2, u1, u2, u1, u2)
    runs = []
    for hist in (rng.uniform(-1, 1, 25), rng.uniform(-1, 1, 8)):
        y, _ = P.simulate(STRUCT, PARAMS, np.r_[hist, loop])
        runs.append(y[hist.size + 6:])  # from the first arrival at u1 on
    shift = runs[0] - runs[1]
    assert_allclose(shift, shift[0], rtol=0, atol=1e-13)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), repeats=st.lists(st.integers(1, 4), min_size=5,
                                                       max_size=5))
def test_rate_independence(seed, repeats):
    """The same sequence of values at another speed (held samples, extra samples on the
    monotone legs between them) gives the same output values."""
    u = _walk(300, seed)
    hold = np.repeat(u, np.resize(repeats, u.size))
    fine = np.concatenate([np.linspace(a, b, 4)[:-1] for a, b in pairwise(u)] + [u[-1:]])
    y, _ = P.simulate(STRUCT, PARAMS, u)
    y_hold, _ = P.simulate(STRUCT, PARAMS, hold)
    y_fine, _ = P.simulate(STRUCT, PARAMS, fine)
    assert_allclose(y_hold[np.cumsum(np.resize(repeats, u.size)) - 1], y, rtol=0, atol=1e-13)
    assert_allclose(y_fine[::3], y, rtol=0, atol=1e-13)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), top=st.floats(-0.5, 1.0), depth=st.floats(0.05, 1.0))
def test_return_point_memory(seed, top, depth):
    """A minor loop closes: wandering below a reversal point and coming back to it restores
    the output it had there."""
    rng = np.random.default_rng(seed)
    bottom = max(top - depth, -1.0)
    wander = rng.uniform(bottom, top - 1e-9, 20)
    u = np.r_[rng.uniform(-1, 1, 10), bottom, top, bottom, wander, top]
    y, _ = P.simulate(STRUCT, PARAMS, u)
    assert y[-1] == pytest.approx(y[11], abs=1e-13)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_branches_are_monotone_for_non_negative_weights(seed):
    params = P.PreisachParams.from_masses(_masses(seed, sparsity=0.5))
    u = _walk(500, seed)
    y, _ = P.simulate(STRUCT, params, u)
    assert np.all(np.diff(y) * np.sign(np.diff(u)) >= -1e-13)


def test_inverse_undoes_the_model():
    u = _walk(3000, 4)
    y, x_end = P.simulate(STRUCT, PARAMS, u)
    u_hat, x_hat = P.invert(STRUCT, PARAMS, y)
    # strictly positive masses: every branch is strictly monotone, the root unique; bisection
    # to 1e-12 plus the exact linear step inside the piecewise-linear branch
    assert_allclose(u_hat, u, rtol=0, atol=1e-9)
    assert_allclose(x_hat, x_end, rtol=0, atol=1e-9)


def test_inverse_of_a_flat_model_is_refused():
    with pytest.raises(FitDivergedError, match="no inverse"):
        P.invert(STRUCT, P.PreisachParams(np.zeros((L, L))), np.zeros(3))


def _forcs(params: P.PreisachParams, levels: np.ndarray) -> np.ndarray:
    """FORCs by simulation: negative saturation, up to alpha, down through the levels."""
    y = np.full((levels.size, levels.size), np.nan)
    for i, alpha in enumerate(levels):
        down = levels[: i + 1][::-1]
        out, _ = P.simulate(STRUCT, params, np.r_[np.linspace(-1, alpha, 5), down], x0=[-1.0])
        y[i, : i + 1] = out[5:][::-1]
    return y


def test_forc_identification_round_trip():
    h = P.grid(L)
    est = everett_from_forcs(h, h, _forcs(PARAMS, h))
    assert_allclose(est.everett, PARAMS.everett, rtol=0, atol=1e-13)  # eq. 9.4, exact
    assert est.offset == pytest.approx(PARAMS.offset, abs=1e-13)
    fine = P.grid(2 * L - 1)  # FORCs measured on a finer grid, resampled onto the model's
    est = everett_from_forcs(fine, fine, _forcs(PARAMS, fine), levels=L)
    assert_allclose(est.everett, PARAMS.everett, rtol=0, atol=1e-13)
    with pytest.raises(ValueError, match="contain every alpha"):
        everett_from_forcs(h, h[::2], _forcs(PARAMS, h)[:, ::2])


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_least_squares_recovers_known_weights(sign):
    """Without FORCs: simulated data of a known model (counter-clockwise weights >= 0, or
    clockwise ones, <= 0 off the diagonal) -> the same masses (the regressor is exact)."""
    m = _masses(5, sparsity=0.3)
    m[np.tril_indices(L - 1, -1)] *= sign
    truth = P.PreisachParams.from_masses(m, offset=-0.1)
    structure = P.PreisachStructure(levels=L, smoothing=0.0)
    u = _walk(3000, 6)
    y, _ = P.simulate(structure, truth, u)
    result = fit_preisach(u, y, structure)
    assert_allclose(result.params.masses(), m, rtol=0, atol=1e-9)
    assert result.params.offset == pytest.approx(-0.1, abs=1e-9)
    assert result.cost < 1e-16 and result.n_starts == 2
    assert ("counter-clockwise" in result.message) == (sign > 0)


def test_fit_honours_accept():
    u = _walk(1000, 7)
    y, _ = P.simulate(STRUCT, PARAMS, u)
    structure = P.PreisachStructure(levels=L, orientation="counterclockwise")
    with pytest.raises(FitDivergedError, match="because I say so"):
        fit_preisach(u, y, structure, accept=lambda p: False, accept_reason="because I say so")
    # vetoing the better orientation leaves the other
    auto = fit_preisach(u, y, P.PreisachStructure(levels=L),
                        accept=lambda p: np.all(p.masses()[np.tril_indices(L - 1, -1)] < 1e-12))
    assert "clockwise" in auto.message and "counter" not in auto.message
    y_fit, _ = P.simulate(auto.structure, auto.params, u)
    assert auto.cost == pytest.approx(np.sum((y_fit - y) ** 2), rel=1e-9)


def test_params_and_structure_round_trip_through_json():
    d = json.loads(json.dumps(PARAMS.to_dict()))
    assert P.PreisachParams.from_dict(d) == PARAMS
    assert P.PreisachStructure(**json.loads(json.dumps(asdict(STRUCT)))) == STRUCT


@pytest.mark.parametrize("bad", [np.ones((L, L)), np.full((L, L), np.nan), np.zeros((L, 3))])
def test_params_validation(bad):
    with pytest.raises(ValueError):
        P.PreisachParams(bad)


@pytest.mark.parametrize("x0", [[0.0], [-1.0, 0.5, 0.6], [-1.0, 0.5, -0.2, 0.6], [-1.0, 1.5]])
def test_invalid_states_are_refused(x0):
    with pytest.raises(ValueError, match="state"):
        P.simulate(STRUCT, PARAMS, np.zeros(2), x0=x0)


@pytest.mark.parametrize("mode", ["direct", "inverse"])
def test_compensator_on_the_virtual_sensor(mode):
    comp = fit_compensator(simulate_experiment("sine", 1), model="preisach", mode=mode)
    scores = evaluate(comp, simulate_experiment("sine", 2))
    # measured when written: direct 0.9993, inverse 0.9965, the line 0.9384
    assert np.isfinite(scores["r2"]) and scores["r2"] > scores["linear_r2"]
    again = compensator_from_dict(json.loads(json.dumps(compensator_to_dict(comp))))
    assert again.params == comp.params and again.structure == comp.structure
    assert get_family("preisach").default_size == comp.structure.levels == 20


def test_records_round_trip_and_old_model_files_load():
    small = P.PreisachParams(everett=[[0, 0, 0], [0.5, 0, 0], [1.25, 0.75, 0]], offset=0.2)
    # params as written before the move (lower-triangle rows), structure as asdict wrote it
    old_params = {"everett": [[0.5], [1.25, 0.75]], "offset": 0.2}
    old_structure = {"levels": 9, "dt": 0.025, "capacity": 22, "smoothing": 1e-05,
                     "orientation": "auto"}
    assert P.PreisachParams.from_dict(old_params) == small
    assert small.to_dict() == old_params
    assert P.PreisachStructure.from_dict(old_structure) == STRUCT
    assert STRUCT.to_dict() == old_structure
    assert P.PreisachParams.from_dict(json.loads(json.dumps(PARAMS.to_dict()))) == PARAMS
    assert hash(STRUCT) == hash(P.PreisachStructure(**old_structure))  # cacheable
    assert get_family("preisach").n_params(STRUCT, PARAMS) == L * (L - 1) // 2 + 1
