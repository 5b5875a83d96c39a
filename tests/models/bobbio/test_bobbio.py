"""Bobbio-Marrucci chain (sec. 2.1.4, eq. 2.5, fig. 2.8): constraints, non-local memory, rate
independence, minor loops, exact inverse, linear fit."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal
from scipy.optimize import brentq

from hystkit.compensation import evaluate, fit_compensator
from hystkit.errors import FitDivergedError
from hystkit.models import bobbio, get_family, numerical_linearisation
from hystkit.models.bobbio import candidate_thresholds, fit_bobbio
from hystkit.sensors import simulate_experiment

STRUCT = bobbio.BobbioStructure(n_springs=5)
PARAMS = bobbio.BobbioParams(compliance=[0.5, 0.2, 0.1, 0.3, 0.4],
                             friction=[0.1, 0.15, 0.2, 0.25], offset=0.1)
BIG = 2.0  # beyond every play radius (A_5 = 0.7): an excursion to +-BIG wipes all memory


def _input(n: int = 3000, seed: int = 0) -> np.ndarray:
    t = np.arange(n) * 0.025
    noise = np.random.default_rng(seed).standard_normal(n)
    return np.sin(np.pi * t) * np.exp(-t / 40) + 0.3 * np.sin(2.3 * t) + 0.05 * noise


def _ramps(*extrema: float, n: int = 50) -> np.ndarray:
    """Piecewise-linear path through the given extrema, ``n`` samples per leg."""
    legs = [np.linspace(a, b, n + 1)[1:] for a, b in itertools.pairwise(extrema)]
    return np.concatenate([[extrema[0]], *legs])


@settings(max_examples=50, deadline=None)
@given(friction=st.lists(st.floats(1e-3, 2.0), min_size=1, max_size=6),
       seed=st.integers(0, 10_000))
def test_every_state_obeys_eq_2_5_and_the_chain_is_a_sum_of_plays(friction, seed):
    """|F_k - F_k+1| <= a_k after every sample (eq. 2.5), and each force is the play operator
    of the applied force with radius a_1 + .. + a_k-1 (plays compose by adding radii)."""
    n = len(friction) + 1
    s = bobbio.BobbioStructure(n_springs=n)
    p = bobbio.BobbioParams(compliance=np.ones(n), friction=friction)
    u = 3 * np.random.default_rng(seed).standard_normal(200)
    f, _ = bobbio.forces(s, p, u)
    chain = np.column_stack([u, f])
    # F_k - a_k is rounded once: allow one ulp of the forces
    assert np.all(np.abs(np.diff(chain, axis=1)) <= p.friction + 4e-16 * np.abs(chain[:, 1:]))
    for k, radius in enumerate(p.radii):
        play, prev = np.empty_like(u), u[0]
        for i, u_i in enumerate(u):
            prev = max(u_i - radius, min(u_i + radius, prev))  # eq. 2.11
            play[i] = prev
        # one clip with the summed radius vs a chain of clips: rounding of the partial sums
        assert_allclose(f[:, k], play, rtol=0, atol=1e-13)


def _run(extrema: tuple[float, ...], then: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Output at the end of a history through ``extrema`` (from rest at 0), then the outputs
    and final state along ``then``."""
    path = np.concatenate([[0.0], np.asarray(extrema)])
    y, x = bobbio.simulate(STRUCT, PARAMS, path)
    y_then, x_then = bobbio.simulate(STRUCT, PARAMS, then, x0=x)
    return y[-1], y_then, x_then


def test_non_local_memory_paths_pq_and_pr_of_fig_2_8():
    """Two histories reach the same point P (same input and output) with different internal
    states; the same decreasing input then follows different paths (PQ vs PR, fig. 2.8), and a
    later excursion beyond every threshold wipes the difference out."""
    f_p, f_a = 0.4, -0.3
    down = np.linspace(f_p, -0.3, 61)[1:]
    y_a, *_ = _run((BIG, f_a, f_p), down)  # ascending into P from a reversal at f_a

    def gap(f_b: float) -> float:  # descending into P from a reversal at f_b
        return _run((-BIG, f_b, f_p), down)[0] - y_a

    f_b = brentq(gap, f_p, BIG, xtol=1e-15)
    wipe = _ramps(f_p, BIG, -0.5, 0.2)[1:]
    y_a, path_a, _ = _run((BIG, f_a, f_p), np.concatenate([down, wipe]))
    y_b, path_b, _ = _run((-BIG, f_b, f_p), np.concatenate([down, wipe]))
    assert y_a == pytest.approx(y_b, abs=1e-12)  # the same point P
    pq, pr = path_a[:down.size], path_b[:down.size]
    assert np.max(np.abs(pq - pr)) > 0.05  # two different decreasing paths
    # a local-memory model (Chua-Stromsmoe) could not do this: its future depends on P only
    after = slice(down.size + 50, None)  # once the input has reached BIG
    assert_array_equal(path_a[after], path_b[after])  # wiped out: identical, bit for bit


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), n_insert=st.integers(1, 5))
def test_rate_independence(seed, n_insert):
    """Only the sequence of input values matters: inserting samples on the monotone path
    between two samples (a slower input) leaves the output at the original samples unchanged,
    bit for bit, and dt plays no role."""
    rng = np.random.default_rng(seed)
    u = 2 * rng.standard_normal(60)
    fine = [u[:1]]
    for a, b in itertools.pairwise(u):
        fine.append(a + (b - a) * np.sort(rng.uniform(0, 1, n_insert)))
        fine.append([b])
    fine = np.concatenate(fine)
    y, x = bobbio.simulate(STRUCT, PARAMS, u)
    y_fine, x_fine = bobbio.simulate(bobbio.BobbioStructure(n_springs=5, dt=1e-3), PARAMS, fine)
    assert_array_equal(y_fine[:: n_insert + 1], y)
    assert_array_equal(x_fine, x)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), lo=st.floats(-1.5, 1.5), width=st.floats(0.01, 2.0))
def test_minor_loops_close_after_one_cycle(seed, lo, width):
    """Cycling between two inputs after any history: from the first reversal on, the loop is
    closed; the state at the top returns exactly and later cycles retrace the second one."""
    history = 2 * np.random.default_rng(seed).standard_normal(30)
    _, x = bobbio.simulate(STRUCT, PARAMS, history)
    cycle = _ramps(lo + width, lo, lo + width, n=20)[1:]
    _, x1 = bobbio.simulate(STRUCT, PARAMS, np.concatenate([[lo + width], cycle]), x0=x)
    y2, x2 = bobbio.simulate(STRUCT, PARAMS, cycle, x0=x1)
    y3, _ = bobbio.simulate(STRUCT, PARAMS, cycle, x0=x2)
    assert_array_equal(x2, x1)
    assert_array_equal(y3, y2)
    # the first descent may still follow the branch the history arrived on: not asserted


@settings(max_examples=40, deadline=None)
@given(compliance=st.lists(st.floats(0, 5), min_size=5, max_size=5),
       friction=st.lists(st.floats(1e-3, 0.5), min_size=4, max_size=4))
def test_loops_always_run_one_way(compliance, friction):
    """Ascending branches lie below descending ones for any springs: the signed loop area
    sum y du is <= 0. The virtual sensor's position(sensor) loop has the other orientation,
    which is why a direct (sensor -> position) fit can only find the straight line."""
    p = bobbio.BobbioParams(compliance=compliance, friction=friction)
    u = _ramps(-BIG, BIG, -BIG, BIG, n=200)
    y, _ = bobbio.simulate(STRUCT, p, u)
    last = slice(-401, None)  # the last full cycle, -BIG -> BIG -> -BIG... closed
    area = np.sum(0.5 * (y[last][1:] + y[last][:-1]) * np.diff(u[last]))
    assert area <= 1e-12


def test_the_virtual_sensor_loop_has_the_opposite_orientation():
    rec = simulate_experiment("sine", 1)
    s, p = rec.sensor - rec.sensor.mean(), rec.position - rec.position.mean()
    area = np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(s))  # position as a function of sensor
    assert area > 0


def test_inverse_undoes_forward_exactly():
    u = _input()
    y, x_end = bobbio.simulate(STRUCT, PARAMS, u)
    u_hat, x_hat = bobbio.invert(STRUCT, PARAMS, y)
    # a piecewise-linear walk: exact up to rounding in the segment sums
    assert_allclose(u_hat, u, rtol=0, atol=1e-12)
    assert_allclose(x_hat, x_end, rtol=0, atol=1e-12)


def test_inverse_with_a_rigid_first_spring_stays_consistent():
    # c_1 = 0: Y is flat while piston 1 sticks; the inverse still reproduces the output
    p = bobbio.BobbioParams(compliance=[0.0, 0.2, 0.1, 0.3, 0.4], friction=PARAMS.friction)
    y, _ = bobbio.simulate(STRUCT, p, _input())
    u_hat, _ = bobbio.invert(STRUCT, p, y)
    assert_allclose(bobbio.simulate(STRUCT, p, u_hat)[0], y, rtol=0, atol=1e-12)


def test_inverse_without_any_compliance_is_reported():
    p = bobbio.BobbioParams(compliance=np.zeros(5), friction=PARAMS.friction)
    with pytest.raises(FitDivergedError, match="all compliances are zero"):
        bobbio.invert(STRUCT, p, np.array([0.0, 1.0]))


def test_fit_recovers_compliances_for_known_thresholds():
    u = _input(8000)
    s = bobbio.BobbioStructure(n_springs=6)
    truth = bobbio.BobbioParams(compliance=[0.3, 0.2, 0.0, 0.1, 0.4, 0.05],
                                friction=candidate_thresholds(s, u)[6], offset=0.1)
    y, _ = bobbio.simulate(s, truth, u)
    result = fit_bobbio(u, y, s)
    assert result.cost < 1e-20
    assert_array_equal(result.params.friction, truth.friction)
    # non-negative least squares on noise-free data: exact up to conditioning (~1e-13)
    assert_allclose(result.params.compliance, truth.compliance, rtol=0, atol=1e-10)
    assert result.params.offset == pytest.approx(0.1, abs=1e-10)


def test_acceptance_test_rejections_are_reported():
    u = _input(500)
    with pytest.raises(FitDivergedError, match="rejected .no thanks."):
        fit_bobbio(u, u, STRUCT, accept=lambda p: False, accept_reason="no thanks")


def test_params_round_trips_and_validation():
    assert bobbio.BobbioParams.from_dict(PARAMS.to_dict()) == PARAMS
    assert get_family("bobbio").make_structure(0.025, 5) == STRUCT
    with pytest.raises(ValueError, match="compliance"):
        bobbio.BobbioParams(compliance=[-0.1, 1.0], friction=[0.1])
    with pytest.raises(ValueError, match="friction"):
        bobbio.BobbioParams(compliance=[0.1, 1.0], friction=[0.0])
    with pytest.raises(ValueError, match="1 values"):
        bobbio.BobbioParams(compliance=[0.1, 1.0], friction=[0.1, 0.2])
    with pytest.raises(ValueError):
        bobbio.BobbioStructure(n_springs=0)


def test_compensator_on_the_virtual_sensor():
    fit_rec, val_rec = simulate_experiment("sine", 1), simulate_experiment("sine", 2)
    inverse = evaluate(fit_compensator(fit_rec, model="bobbio", mode="inverse"), val_rec)
    assert inverse["r2"] > inverse["linear_r2"]
    direct = evaluate(fit_compensator(fit_rec, model="bobbio", mode="direct"), val_rec)
    # the wrong loop orientation (test above): every hysteretic compliance is zero and the
    # fit is the least-squares line, the same as the baseline up to rounding
    assert direct["r2"] == pytest.approx(direct["linear_r2"], abs=1e-9)


# --- the family protocol: loop blocks, rest states, at(dt), records, linearisation ---------

FAMILY = get_family("bobbio")


def _x_memory() -> np.ndarray:
    """A state the chain reaches (eq. 2.5 holds with F_1 = 0.1), piston 1 off its threshold
    (run when a test asks: at import, every xdist worker compiled the kernel while collecting)."""
    return bobbio.simulate(STRUCT, PARAMS, _ramps(0.0, 1.5, -0.6, 0.2, 0.1))[1]


# eq. 2.5 strictly inside for F_1 = 0.1: no piston on its threshold, the step is smooth here
X_INSIDE = np.array([0.12, 0.05, -0.1, 0.0])


@pytest.mark.parametrize("inverse", [False, True])
def test_block_equals_step_from_a_non_rest_state(inverse, drive):
    rng = np.random.default_rng(4)
    x0 = _x_memory()
    signal = np.cumsum(0.15 * rng.standard_normal(400))
    if inverse:
        signal = bobbio.simulate(STRUCT, PARAMS, signal, x0=x0)[0] + 0.01 * rng.standard_normal(400)
    run = FAMILY.invert_step if inverse else FAMILY.step
    blk = FAMILY.block(STRUCT, PARAMS, inverse)
    assert blk.n_state == 4
    out_blk, x_blk = drive(blk, x0, signal, off=2)
    out_ref, x_ref = drive(lambda x, v: run(STRUCT, PARAMS, x, v), x0, signal)
    assert np.all(np.isfinite(out_ref))
    assert_allclose(out_blk, out_ref, rtol=0, atol=1e-12)
    assert_allclose(x_blk, x_ref, rtol=0, atol=1e-12)
    assert np.ptp(x_ref[:, -1]) > 0.5  # the last piston slides, memory is exercised


def test_inverse_without_any_compliance_is_nan_in_block_and_step(drive):
    rigid = bobbio.BobbioParams(compliance=np.zeros(3), friction=[0.1, 0.2])
    s = bobbio.BobbioStructure(n_springs=3)
    u_blk, x_blk = drive(FAMILY.block(s, rigid, True), [0.0, 0.0], [0.5], off=1)
    u_ref, x_ref = drive(lambda x, v: FAMILY.invert_step(s, rigid, x, v), [0.0, 0.0], [0.5])
    assert np.isnan(u_blk[0]) and np.isnan(u_ref[0])
    assert np.all(np.isnan(x_blk)) and np.all(np.isnan(x_ref))
    with pytest.raises(FitDivergedError):
        bobbio.invert(s, rigid, np.array([0.0, 0.5]), x0=0.0)


@pytest.mark.parametrize("value", [-0.8, 0.0, 0.35])
def test_rest_state_is_the_start_of_runs_and_a_fixed_point(value):
    x_fwd = FAMILY.rest_state(STRUCT, PARAMS, value)
    y, x_next = FAMILY.step(STRUCT, PARAMS, x_fwd, value)
    assert_array_equal(x_next, x_fwd)
    assert bobbio.simulate(STRUCT, PARAMS, np.full(3, value))[0] == pytest.approx([y] * 3)
    x_inv = FAMILY.rest_state(STRUCT, PARAMS, value, inverse=True)
    u_hat, x_next = FAMILY.invert_step(STRUCT, PARAMS, x_inv, value)
    assert_allclose(x_next, x_inv, rtol=0, atol=1e-12)
    assert FAMILY.step(STRUCT, PARAMS, x_inv, u_hat)[0] == pytest.approx(value, abs=1e-12)
    assert_allclose(bobbio.invert(STRUCT, PARAMS, np.full(3, value))[0], u_hat, atol=1e-12)


def test_at_any_dt_is_the_same_rate_independent_model():
    u = _input(500)
    y, _ = FAMILY.simulate(STRUCT, PARAMS, u)
    for dt in (0.001, 0.025, 0.4):
        other = FAMILY.at(STRUCT, dt)
        assert other.dt == dt and other.n_springs == STRUCT.n_springs
        assert_array_equal(FAMILY.simulate(other, PARAMS, u)[0], y)


def test_records_round_trip_and_old_model_files_load():
    import json

    d = PARAMS.to_dict()
    assert bobbio.BobbioParams.from_dict(json.loads(json.dumps(d))) == PARAMS
    assert bobbio.BobbioStructure.from_dict(STRUCT.to_dict()) == STRUCT
    old = {"compliance": [0.5, 0.2, 0.1, 0.3, 0.4], "friction": [0.1, 0.15, 0.2, 0.25],
           "offset": 0.1}  # as written by hystkit before the move
    assert d == old and bobbio.BobbioParams.from_dict(old) == PARAMS
    old_structure = {"n_springs": 5, "dt": 0.025}  # asdict(structure)
    assert STRUCT.to_dict() == old_structure
    assert bobbio.BobbioStructure(**old_structure) == STRUCT
    assert PARAMS != bobbio.BobbioParams.from_dict({**old, "offset": 0.2})


def test_analytical_linearisation_matches_numerical():
    x = X_INSIDE
    assert_array_equal(FAMILY.step(STRUCT, PARAMS, x, 0.1)[1], x)
    for u in (0.05, 0.45, -1.2, 0.15):  # sticking, partly sliding, all sliding, sticking
        exact = FAMILY.linearise(STRUCT, PARAMS, x, u)
        approx = numerical_linearisation(lambda xx, uu: FAMILY.step(STRUCT, PARAMS, xx, uu),
                                         x, u, rel_step=1e-7)
        for e, a in zip(exact, approx):
            assert_allclose(e, a, rtol=1e-6, atol=1e-8)


def test_inverse_linearisation_is_the_derivative_along_the_motion():
    x = X_INSIDE

    def run(xx, yy):
        return FAMILY.invert_step(STRUCT, PARAMS, xx, yy)

    y_stick = FAMILY.step(STRUCT, PARAMS, x, 0.05)[0]  # piston 1 holds: interior, smooth
    y_slide = FAMILY.step(STRUCT, PARAMS, x, 0.45)[0]  # pistons slide, loading upwards
    for y, one_sided in ((y_stick, False), (y_slide, True)):
        a, b, c, d = FAMILY.linearise(STRUCT, PARAMS, x, y, inverse=True)
        h = 1e-7
        if one_sided:  # a further rise in y continues the motion, from the same state
            (u1, x1), (u0, x0) = run(x, y + h), run(x, y)
            assert_allclose(d, (u1 - u0) / h, rtol=1e-5)
            assert_allclose(b, (x1 - x0) / h, rtol=1e-5, atol=1e-8)
        else:
            num = numerical_linearisation(run, x, y)
            for e, n in zip((a, b, c, d), num):
                assert_allclose(e, n, rtol=1e-6, atol=1e-8)
