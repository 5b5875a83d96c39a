"""Kuhnen / modified PI model (eq. 2.6-2.19): operators, inverse, creep, identification."""

import itertools
import json
from dataclasses import asdict

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.compensation import evaluate, fit_compensator
from hystkit.errors import FitDivergedError
from hystkit.models import FAMILIES, numerical_linearisation, pi
from hystkit.models.pi import MIN_SLOPE, fit_pi
from hystkit.sensors import simulate_experiment

DT = 0.025
STRUCT = pi.PiStructure(play_thresholds=(0.0, 0.2, 0.4, 0.6, 0.8), n_deadzone=2,
                        creep_rates=(10.0, 1.0, 0.1), dt=DT)
# S has a steep and a flat side; the creep weights have mixed signs
PARAMS = pi.PiParams(w_h=[1.0, 0.3, -0.2, 0.2, 0.1], w_s=[0.3, 0.5, 1.0, -0.4, 0.2],
                     d_s=[-0.8, -0.3, 0.0, 0.4, 0.9], w_k=[0.2, -0.1, 0.3], b=0.05)
RATE_INDEPENDENT = pi.PiStructure(play_thresholds=STRUCT.play_thresholds, n_deadzone=2, dt=DT)
PARAMS_RI = pi.PiParams(w_h=PARAMS.w_h, w_s=PARAMS.w_s, d_s=PARAMS.d_s, b=PARAMS.b)


def _input(n: int = 4000, seed: int = 0) -> np.ndarray:
    t = np.arange(n) * DT
    noise = np.random.default_rng(seed).standard_normal(n)
    return np.sin(np.pi * t) * np.exp(-t / 80) + 0.3 * np.sin(2.3 * t) + 0.05 * noise


def _single_play(r: float) -> tuple[pi.PiStructure, pi.PiParams]:
    """Output = the play of threshold r alone (S linear, no creep)."""
    return pi.PiStructure(play_thresholds=(0.0, r), dt=DT), pi.PiParams(w_h=[0.0, 1.0])


def test_inverse_kernel_matches_invert_step():
    u = _input(500)
    y, _ = pi.simulate(STRUCT, PARAMS, u)
    u_hat, x_end = pi.invert(STRUCT, PARAMS, y, x0=u[0])
    x, ref = np.full(8, u[0]), []
    for y_n in y:
        e, x = pi.invert_step(STRUCT, PARAMS, x, y_n)
        ref.append(e)
    # both form the inverse plays from the forward ones, the reference with numpy's cumsum
    assert_allclose(u_hat, ref, rtol=0, atol=1e-13)
    assert_allclose(x_end, x, rtol=0, atol=1e-13)


def test_play_closed_forms_eq_2_11():
    r = 0.3
    s, p = _single_play(r)
    up = np.linspace(0.0, 1.0, 101)
    y, _ = pi.simulate(s, p, up, x0=0.0)
    # from rest at 0 the play holds 0 until the input passes r, then lags it by r
    assert_allclose(y, np.maximum(up - r, 0.0), rtol=0, atol=1e-15)
    # a reversal at 1: flat while the input travels 2 r back, then it leads the input by r
    down = np.linspace(1.0, -0.5, 151)
    y, _ = pi.simulate(s, p, down, x0=np.array([1.0, 1.0 - r]))
    assert_allclose(y, np.where(down >= 1.0 - 2 * r, 1.0 - r, down + r), rtol=0, atol=1e-15)


def test_operators_by_hand():
    # y = S[H + K + b] on the first sample from a known state (eq. 2.7, 2.12, 2.14)
    x0 = np.array([0.1, 0.2, -0.1, 0.0, 0.3, 0.5, -0.2, 0.4])
    u0 = 0.45
    p = np.maximum(u0 - np.array(STRUCT.play_thresholds),
                   np.minimum(u0 + np.array(STRUCT.play_thresholds), x0[:5]))
    c = 1 - np.exp(-np.array([10.0, 1.0, 0.1]) * DT)
    z = x0[5:] + c * (u0 - x0[5:])
    v = PARAMS.w_h @ p + PARAMS.w_k @ z + PARAMS.b
    s = (0.3 * min(v + 0.8, 0) + 0.5 * min(v + 0.3, 0) + v - 0.4 * max(v - 0.4, 0)
         + 0.2 * max(v - 0.9, 0))
    y, x_end = pi.simulate(STRUCT, PARAMS, np.array([u0]), x0=x0)
    assert y[0] == pytest.approx(s, abs=1e-15)
    assert_allclose(x_end, np.concatenate([p, z]), rtol=0, atol=1e-16)


@settings(max_examples=60, deadline=None)
@given(turns=st.lists(st.floats(-1, 1), min_size=2, max_size=12),
       fine=st.integers(2, 9), coarse=st.integers(1, 3))
def test_rate_independence(turns, fine, coarse):
    """Without creep only the turning points matter: the same path walked with more or fewer
    samples per segment gives the same outputs at the turning points."""
    def walk(k):
        return np.concatenate([[turns[0]]] + [np.linspace(a, b, k + 1)[1:]
                                              for a, b in itertools.pairwise(turns)])
    y_fine, x_fine = pi.simulate(RATE_INDEPENDENT, PARAMS_RI, walk(fine), x0=0.0)
    y_coarse, x_coarse = pi.simulate(RATE_INDEPENDENT, PARAMS_RI, walk(coarse), x0=0.0)
    # the play recursion is exact on linear segments; only the rounding of linspace differs
    assert_allclose(y_fine[::fine], y_coarse[::coarse], rtol=0, atol=1e-12)
    assert_allclose(x_fine, x_coarse, rtol=0, atol=1e-12)


def test_minor_loops_close_and_the_major_branch_is_resumed():
    turns = [0.0, 1.0, -0.2, 0.6, 0.1, 0.6, 1.0]
    u = np.concatenate([np.linspace(a, b, 200)[1:] for a, b in itertools.pairwise(turns)])
    y, _ = pi.simulate(RATE_INDEPENDENT, PARAMS_RI, u, x0=0.0)
    ends = np.cumsum([199] * 6) - 1  # index of each turning point
    # the minor loop 0.6 -> 0.1 -> 0.6 closes (return-point memory) ...
    assert y[ends[4]] == pytest.approx(y[ends[2]], abs=1e-14)
    # ... and back at the previous maximum the output is that of the first visit
    assert y[ends[5]] == pytest.approx(y[ends[0]], abs=1e-14)
    assert abs(y[ends[3]] - y[ends[2]]) > 0.05  # the loop is a loop, not a line


def _random_params(rng: np.random.Generator, structure: pi.PiStructure) -> pi.PiParams:
    n, m = structure.n_play, structure.n_deadzone
    slopes = rng.uniform(0.2, 2.0, n)  # partial sums W_i > 0: an invertible PI operator
    up, down = rng.uniform(0.2, 2.0, m), rng.uniform(0.2, 2.0, m)
    w_s = np.concatenate([np.diff(np.r_[1.0, down])[::-1], [1.0], np.diff(np.r_[1.0, up])])
    d = np.cumsum(rng.uniform(0.1, 0.4, m))
    return pi.PiParams(w_h=np.diff(slopes, prepend=0.0), w_s=w_s,
                       d_s=np.concatenate([-d[::-1], [0.0], d]),
                       w_k=rng.uniform(0.0, 0.5, structure.n_creep), b=rng.uniform(-0.2, 0.2))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), creep=st.booleans())
def test_inverse_undoes_the_model(seed, creep):
    """eq. 2.19: S^-1 then the inverse plays; with creep the creep memory is subtracted first.
    Both are explicit per sample, so compensator o model = identity to rounding."""
    structure = STRUCT if creep else RATE_INDEPENDENT
    rng = np.random.default_rng(seed)
    params = _random_params(rng, structure)
    u = 1.5 * _input(800, seed)
    y, x_end = pi.simulate(structure, params, u)
    u_hat, x_hat = pi.invert(structure, params, y)
    # thresholds and weights of the inverse are sums/quotients of O(1) numbers: a few ulps,
    # amplified by slopes down to 0.2
    assert_allclose(u_hat, u, rtol=0, atol=1e-12)
    assert_allclose(x_hat, x_end, rtol=0, atol=1e-12)


def test_inverse_continues_from_a_reached_state_and_negative_polarity():
    u = _input(3000)
    neg = pi.PiParams(w_h=-PARAMS.w_h, w_s=PARAMS.w_s, d_s=PARAMS.d_s, w_k=-PARAMS.w_k, b=0.1)
    for params in (PARAMS, neg):
        y, _ = pi.simulate(STRUCT, params, u, x0=0.2)
        _, x_mid = pi.simulate(STRUCT, params, u[:1700], x0=0.2)
        u_hat, _ = pi.invert(STRUCT, params, y[1700:], x0=x_mid)
        assert_allclose(u_hat, u[1700:], rtol=0, atol=1e-12)


def test_inverse_operator_formulas():
    r = np.array(STRUCT.play_thresholds)
    r_inv, w_inv = pi.inverse_pi(r, PARAMS.w_h)
    # r'_i is the initial loading curve at r_i; inverting twice gives the operator back
    loading = [PARAMS.w_h @ np.maximum(r_i - r, 0.0) for r_i in r]
    assert_allclose(r_inv, loading, rtol=1e-15)
    r2, w2 = pi.inverse_pi(r_inv, w_inv)
    assert_allclose(r2, r, atol=1e-15)
    assert_allclose(w2, PARAMS.w_h, atol=1e-14)
    d_inv, ws_inv = pi.inverse_superposition(PARAMS.d_s, PARAMS.w_s)
    v = np.linspace(-2, 2, 401)
    s = pi.deadzone(v[:, None], PARAMS.d_s) @ PARAMS.w_s
    assert_allclose(pi.deadzone(s[:, None], d_inv) @ ws_inv, v, atol=1e-14)
    assert_allclose(d_inv, pi.deadzone(PARAMS.d_s[:, None], PARAMS.d_s) @ PARAMS.w_s,
                    atol=1e-15)  # d'_k = S(d_k)


def test_log_type_creep_step_response():
    """Linear creep operators one decade apart with equal weights w: after a step the creep
    grows by w per decade of time (fig. 2.13), between the fastest and the slowest operator."""
    w = 0.1
    s = pi.PiStructure(play_thresholds=(0.0,), creep_rates=tuple(10.0 ** -np.arange(-1, 5)),
                       dt=DT)  # time constants 0.1 s .. 10^4 s
    p = pi.PiParams(w_h=[1.0], w_k=np.full(6, w))
    n = round(2000 / DT)
    y, _ = pi.simulate(s, p, np.ones(n), x0=0.0)
    t = np.arange(1, n + 1) * DT  # sample k closes the interval ending at (k + 1) dt
    # exact discretisation: the creep state after time t is 1 - exp(-a t)
    assert_allclose(y - 1.0, w * (1 - np.exp(-np.outer(t, s.creep_rates))).sum(axis=1),
                    rtol=1e-12)
    for start in (1.0, 2.5, 7.0, 30.0, 100.0):
        i, j = np.searchsorted(t, [start, 10 * start])
        # the ripple of a sum of exponentials is periodic in log t with period one decade,
        # so the rise over any whole decade is w to within the end effects (< 2 %)
        assert (y[j] - y[i]) == pytest.approx(w, rel=0.02)
    k = (t >= 1.0) & (t <= 1000.0)
    slope = np.polyfit(np.log10(t[k]), y[k], 1)[0]
    assert slope == pytest.approx(w, rel=0.03)  # linear in log t: log(t)-type creep


def test_recovery_of_known_weights():
    u = 1.2 * _input(6000, seed=3)
    y, _ = pi.simulate(STRUCT, PARAMS, u)
    d_inv, _ = pi.inverse_superposition(PARAMS.d_s, PARAMS.w_s)
    exact = fit_pi(u, y, STRUCT, d_inv=d_inv, ridge=0.0)
    for name in ("w_h", "w_s", "d_s", "w_k"):
        # noise-free data and the true S^-1 thresholds: exact up to the solver's rounding
        assert_allclose(getattr(exact.params, name), getattr(PARAMS, name), atol=1e-9)
    assert exact.params.b == pytest.approx(PARAMS.b, abs=1e-9)
    assert exact.cost < 1e-18 and exact.n_starts == 1
    ridged = fit_pi(u, y, STRUCT, d_inv=d_inv)
    # the default ridge only moves the weakly excited slow creep weights, by < 1e-4
    assert_allclose(ridged.params.w_k, PARAMS.w_k, atol=1e-4)
    assert_allclose(ridged.params.w_h, PARAMS.w_h, atol=1e-5)


def test_fit_recovers_a_decreasing_model():
    neg = pi.PiParams(w_h=-PARAMS.w_h, w_s=PARAMS.w_s, d_s=PARAMS.d_s, w_k=-PARAMS.w_k, b=0.1)
    u = _input(5000, seed=4)
    y, _ = pi.simulate(STRUCT, neg, u)
    d_inv, _ = pi.inverse_superposition(neg.d_s, neg.w_s)
    res = fit_pi(u, y, STRUCT, d_inv=d_inv, ridge=0.0)
    assert_allclose(res.params.w_h, neg.w_h, atol=1e-9)
    assert_allclose(res.params.w_k, neg.w_k, atol=1e-9)


def test_fit_constraints_make_the_model_invertible():
    rng = np.random.default_rng(7)
    u = _input(4000, seed=7)
    y = np.tanh(2 * u) + 0.3 * rng.standard_normal(u.size)  # noisy, no hysteresis at all
    res = fit_pi(u, y, STRUCT)
    p = res.params
    slopes = np.cumsum(p.w_h) - np.maximum(-p.w_k, 0).sum()
    assert np.all(slopes >= MIN_SLOPE * (1 - 1e-9))  # the bound of the lifted problem
    assert pi.not_invertible_reason(STRUCT, p) == ""
    y_model, _ = pi.simulate(STRUCT, p, u)
    u_hat, _ = pi.invert(STRUCT, p, y_model)
    assert_allclose(u_hat, u, atol=1e-10)
    assert res.cost == pytest.approx(np.sum((y_model - y) ** 2), rel=1e-12)  # eq. 5.9


def test_fit_checks_accept_once():
    u = _input(1000)
    y, _ = pi.simulate(STRUCT, PARAMS, u)
    calls = []

    def veto(params):
        calls.append(params)
        return False

    with pytest.raises(FitDivergedError, match="inverse wobbles"):
        fit_pi(u, y, STRUCT, accept=veto, accept_reason="inverse wobbles")
    assert len(calls) == 1


def test_not_invertible_model_raises():
    p = pi.PiParams(w_h=[1.0, -1.5, 0.2, 0.1, 0.1], w_s=PARAMS.w_s, d_s=PARAMS.d_s,
                    w_k=[0.0, 0.0, 0.0])  # loading curve slope 1 - 1.5 < 0
    assert "not invertible" in pi.not_invertible_reason(STRUCT, p)
    with pytest.raises(FitDivergedError, match="no inverse"):
        pi.invert(STRUCT, p, _input(10))


def test_params_and_structure_round_trip_through_json():
    structure = FAMILIES["pi"].make_structure(DT, 6)
    d = json.loads(json.dumps(asdict(structure)))
    assert pi.PiStructure(**d) == structure
    back = pi.PiParams.from_dict(json.loads(json.dumps(PARAMS.to_dict())))
    assert back == PARAMS
    assert back != PARAMS_RI


@pytest.mark.parametrize("kwargs", [{"play_thresholds": (0.1, 0.2)},
                                    {"play_thresholds": (0.0, 0.5, 0.5)},
                                    {"creep_rates": (1.0, -1.0)}, {"n_deadzone": -1},
                                    {"dt": 0.0}, {"play_thresholds": (0.0, np.nan)}])
def test_structure_rejects_bad_values(kwargs):
    with pytest.raises(ValueError):
        pi.PiStructure(**kwargs)


@pytest.mark.parametrize("kwargs", [{"d_s": [-0.1, 0.1, 0.2]}, {"d_s": [0.0, -0.1, 0.2]},
                                    {"w_s": [1.0, 1.0], "d_s": [0.0, 1.0]},
                                    {"b": np.inf}, {"w_k": [np.nan]}])
def test_params_reject_bad_values(kwargs):
    base = {"w_h": [1.0], "w_s": [1.0, 1.0, 1.0], "d_s": [-0.5, 0.0, 0.5]}
    with pytest.raises(ValueError):
        pi.PiParams(**{**base, **kwargs})


def test_simulate_rejects_nan_input_and_mismatched_params():
    u = _input(10)
    u[3] = np.nan
    with pytest.raises(ValueError, match="index 3"):
        pi.simulate(STRUCT, PARAMS, u)
    with pytest.raises(ValueError, match="structure"):
        pi.simulate(RATE_INDEPENDENT, PARAMS, _input(10))


@pytest.mark.parametrize("mode", ["direct", "inverse"])
def test_compensator_end_to_end_on_the_virtual_sensor(mode):
    comp = fit_compensator(simulate_experiment("sine", 1), model="pi", mode=mode)
    scores = evaluate(comp, simulate_experiment("sine", 2))
    # fit seed 1, validate seed 2 (default size 10): r2 0.9998 direct, 0.9963 inverse, against
    # 0.9384 for the straight line
    assert np.isfinite(scores["r2"])
    assert scores["r2"] > scores["linear_r2"]
    assert comp.fit_info["n_starts"] == 1


# -- family protocol ----------------------------------------------------------------------

def _history() -> np.ndarray:
    """The forward state after a run: plays on and inside their bands, creep half-settled."""
    return pi.simulate(STRUCT, PARAMS, _input(300, seed=7))[1]


@pytest.mark.parametrize("inverse", [False, True])
def test_block_equals_step_from_a_non_rest_state(inverse):
    u = _input(400, seed=8)[100:]
    x = _history()
    signal = pi.simulate(STRUCT, PARAMS, u, x)[0] if inverse else u
    block = pi.FAMILY.block(STRUCT, PARAMS, inverse)
    run = pi.invert_step if inverse else pi.step
    assert block.n_state == STRUCT.n_play + STRUCT.n_creep
    off = 2
    big = np.zeros(off + block.n_state + 3)
    big[off:off + block.n_state] = x
    for v in signal:
        xn = np.full_like(big, np.nan)  # the block writes its whole slice, nothing else
        out = block.step(block.body, big, xn, off, v)
        ref, x = run(STRUCT, PARAMS, x, v)
        assert out == pytest.approx(ref, abs=1e-12)
        assert_allclose(xn[off:off + block.n_state], x, rtol=0, atol=1e-12)
        assert np.all(np.isnan(np.r_[xn[:off], xn[off + block.n_state:]]))
        big[off:off + block.n_state] = xn[off:off + block.n_state]


def test_inverse_run_in_pieces_is_the_whole_run_bit_for_bit():
    """The state between runs is the forward state the kernel carries (no conversion from
    inverse plays), so splitting a run anywhere changes no bit. Drawn parameters 1 and 4
    moved ~1e-16 - 2e-15 at the pieces' ends when the run kept inverse plays and converted."""
    u = _input(1200, seed=10)
    for seed in (1, 4):
        params = pi.FAMILY.random_params(STRUCT, np.random.default_rng(seed))
        y, _ = pi.simulate(STRUCT, params, u)
        whole, x_whole = pi.invert(STRUCT, params, y)
        head, x = pi.invert(STRUCT, params, y[:1])
        pieces = [head]
        for a, b in ((1, 7), (7, 500), (500, 1200)):
            piece, x = pi.invert(STRUCT, params, y[a:b], x)
            pieces.append(piece)
        assert_array_equal(np.concatenate(pieces), whole)
        assert_array_equal(x, x_whole)


def test_inverse_block_is_refused_for_a_model_without_inverse():
    flat = pi.PiParams(w_h=[1.0, -1.5, 0.2, 0.1, 0.1], w_s=PARAMS.w_s, d_s=PARAMS.d_s,
                       w_k=PARAMS.w_k, b=PARAMS.b)
    with pytest.raises(FitDivergedError, match="no inverse"):
        pi.FAMILY.block(STRUCT, flat, inverse=True)


@pytest.mark.parametrize("inverse", [False, True])
def test_rest_state_is_the_default_start_and_a_fixed_point(inverse):
    run = pi.invert if inverse else pi.simulate
    run_step = pi.invert_step if inverse else pi.step
    signal = _input(300, seed=9)
    if inverse:
        signal = pi.simulate(STRUCT, PARAMS, signal)[0]
    for value in (signal[0], -0.6, 0.9):
        x = pi.FAMILY.rest_state(STRUCT, PARAMS, value, inverse)
        out, x_next = run_step(STRUCT, PARAMS, x, value)
        assert_allclose(x_next, x, rtol=0, atol=1e-12)
        assert out == pytest.approx(run(STRUCT, PARAMS, np.array([value]))[0][0], abs=1e-12)
    x = pi.FAMILY.rest_state(STRUCT, PARAMS, signal[0], inverse)
    assert_allclose(run(STRUCT, PARAMS, signal, x)[0], run(STRUCT, PARAMS, signal)[0],
                    rtol=0, atol=1e-12)


def test_at_re_discretises_the_creep_and_keeps_the_plays():
    fine = pi.FAMILY.at(STRUCT, DT / 4)
    assert fine.play_thresholds == STRUCT.play_thresholds and fine.dt == DT / 4
    assert fine.creep_rates == STRUCT.creep_rates
    assert_allclose(fine.creep_gains, 1 - np.exp(-np.asarray(STRUCT.creep_rates) * DT / 4))
    # an input held over each coarse sample (ZOH) gives the same output at the common
    # instants: the creep operators are exact for a held input, the plays rate independent
    u = _input(800, seed=10)
    y = pi.simulate(STRUCT, PARAMS, u)[0]
    y_fine = pi.simulate(fine, PARAMS, np.repeat(u, 4))[0]
    assert_allclose(y_fine[3::4], y, rtol=0, atol=1e-12)
    # keeping the coarse per-sample gains at the finer step would make creep 4x faster
    too_fast = pi.simulate(STRUCT, PARAMS, np.repeat(u, 4))[0][3::4]
    assert np.max(np.abs(too_fast - y)) > 1e-3


@pytest.mark.parametrize("inverse", [False, True])
def test_linearise_matches_the_numerical_jacobian_off_the_kinks(inverse):
    x = _history()
    u = 0.37  # off every band edge and dead-zone threshold of this state
    if inverse:
        u = pi.step(STRUCT, PARAMS, x, u)[0]
    run = pi.invert_step if inverse else pi.step
    got = pi.FAMILY.linearise(STRUCT, PARAMS, x, u, inverse)
    ref = numerical_linearisation(lambda xx, uu: run(STRUCT, PARAMS, xx, uu), x, u)
    for a, b in zip(got, ref, strict=True):
        assert_allclose(np.asarray(a, float), np.asarray(b, float), rtol=1e-6, atol=1e-8)


def test_linearise_at_rest_is_the_reversal_slope_with_held_plays():
    x = pi.FAMILY.rest_state(STRUCT, PARAMS, 0.1)
    a, b, c, d = pi.FAMILY.linearise(STRUCT, PARAMS, x, 0.1)
    g = STRUCT.creep_gains
    held = np.r_[0.0, np.ones(STRUCT.n_play - 1)]  # r_0 = 0 follows the input
    assert_allclose(np.diag(a), np.r_[held, 1 - g])
    assert_allclose(b, np.r_[1 - held, g])
    v = PARAMS.w_h.sum() * 0.1 + PARAMS.w_k.sum() * 0.1 + PARAMS.b
    s_slope = PARAMS.w_s @ np.where(PARAMS.d_s > 0, v > PARAMS.d_s,
                                    np.where(PARAMS.d_s < 0, v < PARAMS.d_s, True))
    assert d == pytest.approx(s_slope * (PARAMS.w_h[0] + PARAMS.w_k @ g))
    assert_allclose(c, s_slope * np.r_[PARAMS.w_h * held, PARAMS.w_k * (1 - g)])


def test_params_and_structure_are_records_and_old_files_load():
    for record in (STRUCT, PARAMS):
        again = type(record).from_dict(json.loads(json.dumps(record.to_dict())))
        assert again == record
    assert hash(STRUCT) == hash(pi.PiStructure.from_dict(STRUCT.to_dict()))  # cacheable
    # a model file written before the move (hystkit 0.x, identification/family_pi.py)
    old_params = {"w_h": [1.0, 0.3, -0.2, 0.2, 0.1], "w_s": [0.3, 0.5, 1.0, -0.4, 0.2],
                  "d_s": [-0.8, -0.3, 0.0, 0.4, 0.9], "w_k": [0.2, -0.1, 0.3], "b": 0.05}
    old_structure = {"play_thresholds": [0.0, 0.2, 0.4, 0.6, 0.8], "n_deadzone": 2,
                     "creep_rates": [10.0, 1.0, 0.1], "dt": 0.025}
    assert pi.PiParams.from_dict(old_params) == PARAMS
    assert pi.PiStructure.from_dict(old_structure) == STRUCT
    assert PARAMS.to_dict() == old_params and STRUCT.to_dict() == old_structure
