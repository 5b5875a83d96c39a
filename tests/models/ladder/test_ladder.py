"""PWL ladder circuit (sec. 2.1.5): kernels, closed forms, stability limit, quasi-static limit
(the Bobbio-Marrucci chain, sec. 2.1.4), inverse, fit."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.compensation import evaluate, fit_compensator
from hystkit.errors import FitDivergedError
from hystkit.models import bobbio, get_family, ladder, numerical_linearisation
from hystkit.models.ladder import fit_ladder
from hystkit.sensors import simulate_experiment

DT = 0.025
STRUCT3 = ladder.LadderStructure(n_cells=3, dt=DT)
PARAMS3 = ladder.LadderParams(band=[0.1, 0.0, 0.2], conductance=[5.0, 100.0, 1.0],
                              w=[0.8, 0.3, -0.2, 0.4], v_b=0.1)


def _input(n: int = 4000, seed: int = 0) -> np.ndarray:
    t = np.arange(n) * DT
    noise = np.random.default_rng(seed).standard_normal(n)
    return np.sin(np.pi * t) * np.exp(-t / 80) + 0.3 * np.sin(2.3 * t) + 0.05 * noise


def test_kernel_matches_readable_reference():
    u = _input()
    y, x_end = ladder.simulate(STRUCT3, PARAMS3, u)
    y_ref, x_ref = ladder.simulate_reference(STRUCT3, PARAMS3, u)
    assert_array_equal(x_end, x_ref)  # the same Euler arithmetic in the same order
    assert_allclose(y, y_ref, rtol=0, atol=1e-15)  # read-out summed in another order


def test_linear_cell_step_response_closed_form():
    # no dead band: an RC cell, U_n = 1 - (1 - G dt)^n for a unit step from 0 (output first)
    g = 8.0
    s = ladder.LadderStructure(n_cells=1, dt=DT)
    p = ladder.LadderParams(band=[0.0], conductance=[g], w=[0.0, 1.0])
    y, _ = ladder.simulate(s, p, np.ones(100), x0=0.0)
    assert_allclose(y, 1 - (1 - g * DT) ** np.arange(100), rtol=1e-13)


def test_dead_band_holds_the_charge():
    # |e - U| <= E: no current, the capacitor keeps its voltage for ever (DC memory)
    s = ladder.LadderStructure(n_cells=1, dt=DT)
    p = ladder.LadderParams(band=[0.3], conductance=[10.0], w=[0.0, 1.0])
    u = 0.5 + 0.3 * np.sin(np.arange(500))  # always within 0.5 +- 0.3 of U = 0.5
    y, x_end = ladder.simulate(s, p, u, x0=0.5)
    assert np.all(y == 0.5) and x_end[0] == 0.5


def test_conductances_beyond_the_limit_are_capped():
    fast = ladder.LadderParams(band=[0.1, 0.2], conductance=[1e6, 1e9], w=[0.5, 1.0, 1.0])
    at_cap = ladder.LadderParams(band=[0.1, 0.2], conductance=[20.0, 20.0], w=[0.5, 1.0, 1.0])
    s = ladder.LadderStructure(n_cells=2, dt=DT)
    assert ladder.conductance_limit(s) == 20.0  # slope_cap / (2 dt)
    assert_array_equal(ladder.simulate(s, fast, _input())[0], ladder.simulate(s, at_cap,
                                                                               _input())[0])


@settings(max_examples=80, deadline=None)
@given(bands=st.lists(st.floats(0, 2), min_size=1, max_size=4),
       log_g=st.lists(st.floats(-8, 12), min_size=4, max_size=4),
       cap=st.floats(0.05, 1.0), seed=st.integers(0, 10_000))
def test_stability_limit_bounds_any_parameter_set(bands, log_g, cap, seed):
    """With the limit, every node voltage stays between the extremes of the input and of the
    initial state, whatever the resistors (the Euler step is monotone in every voltage)."""
    n = len(bands)
    s = ladder.LadderStructure(n_cells=n, dt=DT, slope_cap=cap)
    p = ladder.LadderParams(band=bands, conductance=np.exp(log_g[:n]), w=np.ones(n + 1))
    rng = np.random.default_rng(seed)
    u = 3 * rng.standard_normal(300)
    x0 = rng.uniform(-5, 5, n)
    states, _ = ladder.states(s, p, u, x0=x0)
    lo, hi = min(u.min(), x0.min()), max(u.max(), x0.max())
    assert np.all((states >= lo - 1e-12) & (states <= hi + 1e-12))


def test_slow_inputs_give_the_bobbio_marrucci_chain():
    """Fast resistors, slow input: node k follows the play of node k-1 with radius E_k, i.e.
    the rate-independent spring/piston chain with thresholds a_k = E_k (sec. 2.1.4-2.1.5).
    The lag is first order in the input's rate."""
    bands = [0.1, 0.15, 0.2]
    s = ladder.LadderStructure(n_cells=3, dt=DT)
    p = ladder.LadderParams(band=bands, conductance=[1e9] * 3, w=[0.0, 1.0, 1.0, 1.0])
    chain = bobbio.BobbioParams(compliance=[0.0, 1.0, 1.0, 1.0], friction=bands)
    errors = []
    for period in (4000, 40000):
        u = np.sin(2 * np.pi * np.arange(2 * period) / period)
        states, _ = ladder.states(s, p, u)
        forces, _ = bobbio.forces(bobbio.BobbioStructure(n_springs=4), chain, u)
        errors.append(np.max(np.abs(states[1:] - forces[:-1])))  # states lag one sample
    assert errors[1] < 2e-3
    assert errors[0] / errors[1] == pytest.approx(10.0, rel=0.05)  # first order in 1/period


def test_inverse_undoes_forward_to_machine_precision():
    u = _input()
    y, _ = ladder.simulate(STRUCT3, PARAMS3, u)
    u_hat, _ = ladder.invert(STRUCT3, PARAMS3, y)
    assert_allclose(u_hat, u, rtol=0, atol=1e-12)  # output first, then the update (fig. 5.12)


def test_unstable_inverse_is_reported_not_returned_as_nan():
    # the inverse cell sees a self-gain -(1 + w_1 / w_0) = 4 per unit conductance: it blows up
    s = ladder.LadderStructure(n_cells=1, dt=DT)
    p = ladder.LadderParams(band=[0.0], conductance=[15.0], w=[0.2, -1.0])
    y, _ = ladder.simulate(s, p, _input(2000))
    with pytest.raises(FitDivergedError, match="diverged at sample"):
        ladder.invert(s, p, y)
    with pytest.raises(FitDivergedError, match="w_0 = 0"):
        ladder.invert(s, ladder.LadderParams(band=[0.0], conductance=[1.0], w=[0.0, 1.0]), y)


def test_recovers_known_parameters_from_noise_free_data():
    truth = ladder.LadderParams(band=[0.05, 0.2], conductance=[8.0, 0.5], w=[0.8, 0.4, -0.3],
                                v_b=0.1)
    s = ladder.LadderStructure(n_cells=2, dt=DT)
    t = np.arange(8000) * DT
    u = np.sin(np.pi * t) * np.exp(-t / 100) + 0.2 * np.sin(2.3 * t)
    y, _ = ladder.simulate(s, truth, u)
    result = fit_ladder(u, y, s)
    assert result.converged
    assert result.cost < 1e-20
    # noise-free data: the optimum is the truth (finite differences: ~1e-8 relative)
    assert_allclose(result.params.band, truth.band, rtol=1e-6)
    assert_allclose(result.params.conductance, truth.conductance, rtol=1e-6)
    assert_allclose(result.params.w, truth.w, rtol=1e-6)
    assert result.params.v_b == pytest.approx(0.1, rel=1e-6)


def test_acceptance_test_rejections_are_reported():
    u = _input(1000)
    with pytest.raises(FitDivergedError, match="rejected .no thanks."):
        fit_ladder(u, 0.5 * u, ladder.LadderStructure(n_cells=1, dt=DT),
                   starts=[np.array([0.1, 0.0])], max_nfev=3, screen_nfev=2,
                   accept=lambda p: False, accept_reason="no thanks")


def test_params_round_trips_and_validation():
    assert ladder.LadderParams.from_dict(PARAMS3.to_dict()) == PARAMS3
    assert get_family("ladder").make_structure(DT, 3) == STRUCT3
    with pytest.raises(ValueError, match="band"):
        ladder.LadderParams(band=[-0.1], conductance=[1.0], w=[1.0, 1.0])
    with pytest.raises(ValueError, match="conductance"):
        ladder.LadderParams(band=[0.1], conductance=[0.0], w=[1.0, 1.0])
    with pytest.raises(ValueError, match="2 values"):
        ladder.LadderParams(band=[0.1], conductance=[1.0], w=[1.0])
    for bad in ({"n_cells": 0}, {"dt": 0.0}, {"slope_cap": 2.5}):
        with pytest.raises(ValueError):
            ladder.LadderStructure(**bad)


@pytest.mark.parametrize("mode, size", [("direct", None), ("inverse", 1)])
def test_compensator_on_the_virtual_sensor(mode, size):
    # inverse mode with one cell: with the default two, the inverse fitted on seed 1 diverges
    # on seed 2 (docs/models/circuits.md), so it is not asserted here
    comp = fit_compensator(simulate_experiment("sine", 1), size, model="ladder", mode=mode)
    scores = evaluate(comp, simulate_experiment("sine", 2))
    assert scores["r2"] > scores["linear_r2"]


# --- the family protocol: loop blocks, rest states, at(dt), records, linearisation ---------

FAMILY = get_family("ladder")


@pytest.mark.parametrize("inverse", [False, True])
def test_block_equals_step_from_a_non_rest_state(inverse, drive):
    rng = np.random.default_rng(5)
    x0 = np.array([0.6, -0.4, 0.3])
    signal = np.convolve(1.5 * rng.standard_normal(400), np.ones(4) / 4, "same")
    run = FAMILY.invert_step if inverse else FAMILY.step
    blk = FAMILY.block(STRUCT3, PARAMS3, inverse)
    assert blk.n_state == 3
    out_blk, x_blk = drive(blk, x0, signal, off=1)
    out_ref, x_ref = drive(lambda x, v: run(STRUCT3, PARAMS3, x, v), x0, signal)
    assert np.all(np.isfinite(out_ref))
    assert_allclose(out_blk, out_ref, rtol=0, atol=1e-12)
    assert_allclose(x_blk, x_ref, rtol=0, atol=1e-12)
    assert np.ptp(x_ref[:, 2]) > 0.2  # the last section conducts now and then


def test_forward_output_is_linear_in_the_states_to_rounding():
    """The fit solves for ``w`` and ``V_b`` with ``w_0 u + states @ w - V_b``; the run sums the
    same terms in another order."""
    u = _input()
    y, _ = ladder.simulate(STRUCT3, PARAMS3, u)
    s, _ = ladder.states(STRUCT3, PARAMS3, u)
    linear = PARAMS3.w[0] * u + s @ PARAMS3.w[1:] - PARAMS3.v_b
    assert_allclose(y, linear, rtol=0, atol=4 * np.spacing(np.max(np.abs(y))))


def test_inverse_block_refuses_without_w0():
    p = ladder.LadderParams(band=[0.1], conductance=[1.0], w=[0.0, 1.0])
    with pytest.raises(FitDivergedError, match="w_0 = 0"):
        FAMILY.block(ladder.LadderStructure(n_cells=1), p, inverse=True)


@pytest.mark.parametrize("value", [-0.7, 0.0, 0.45])
def test_rest_state_is_the_start_of_runs_and_a_fixed_point(value):
    x_fwd = FAMILY.rest_state(STRUCT3, PARAMS3, value)
    y, x_next = FAMILY.step(STRUCT3, PARAMS3, x_fwd, value)
    assert_array_equal(x_next, x_fwd)
    assert_allclose(ladder.simulate(STRUCT3, PARAMS3, np.full(3, value))[0], y, atol=1e-15)
    x_inv = FAMILY.rest_state(STRUCT3, PARAMS3, value, inverse=True)
    u_hat, x_next = FAMILY.invert_step(STRUCT3, PARAMS3, x_inv, value)
    assert_allclose(x_next, x_inv, rtol=0, atol=1e-12)
    assert_allclose(ladder.invert(STRUCT3, PARAMS3, np.full(3, value))[0], u_hat, atol=1e-12)


def test_at_finer_dt_keeps_the_effective_conductances():
    g = ladder.effective_conductance(STRUCT3, PARAMS3)
    assert g[1] < PARAMS3.conductance[1]  # the limit binds at the fitted dt
    for factor in (0.5, 0.2, 0.05):
        fine = FAMILY.at(STRUCT3, DT * factor)
        assert fine.dt == DT * factor
        assert_allclose(ladder.effective_conductance(fine, PARAMS3), g, rtol=1e-12)
        assert ladder.conductance_limit(fine) == pytest.approx(ladder.conductance_limit(STRUCT3))
        assert FAMILY.at(fine, DT) == STRUCT3  # and back
    assert FAMILY.at(STRUCT3, DT) == STRUCT3


def test_at_coarser_dt_saturates_the_cap_and_stays_monotone():
    half = ladder.LadderStructure(n_cells=3, dt=DT, slope_cap=0.5)
    same = FAMILY.at(half, 2 * DT)
    assert same.slope_cap == pytest.approx(1.0)
    assert ladder.conductance_limit(same) == pytest.approx(ladder.conductance_limit(half))
    coarse = FAMILY.at(STRUCT3, 4 * DT)
    assert coarse.slope_cap == 1.0
    assert ladder.conductance_limit(coarse) == pytest.approx(ladder.conductance_limit(STRUCT3) / 4)
    # monotone Euler step: the voltages stay inside the range of input and start
    states = ladder.states(coarse, PARAMS3, np.ones(300), x0=[0.0, -0.5, 0.5])[0]
    assert np.all(states >= -0.5 - 1e-12) and np.all(states <= 1.0 + 1e-12)


def test_at_finer_dt_converges_to_the_same_circuit():
    u = _input(400)
    t = np.arange(u.size) * DT
    ref, _ = FAMILY.simulate(FAMILY.at(STRUCT3, DT / 32), PARAMS3,
                             np.interp(np.arange(u.size * 32) * DT / 32, t, u))
    gaps = []
    for k in (2, 4, 8):
        y_k, _ = FAMILY.simulate(FAMILY.at(STRUCT3, DT / k), PARAMS3,
                                 np.interp(np.arange(u.size * k) * DT / k, t, u))
        gaps.append(np.max(np.abs(y_k[::k] - ref[::32])))
    assert gaps[0] > gaps[1] > gaps[2]  # forward Euler: first order in the step
    assert gaps[2] < 0.6 * gaps[1] < 0.36 * gaps[0]


def test_records_round_trip_and_old_model_files_load():
    import json

    d = PARAMS3.to_dict()
    assert ladder.LadderParams.from_dict(json.loads(json.dumps(d))) == PARAMS3
    assert ladder.LadderStructure.from_dict(STRUCT3.to_dict()) == STRUCT3
    old = {"band": [0.1, 0.0, 0.2], "conductance": [5.0, 100.0, 1.0],
           "w": [0.8, 0.3, -0.2, 0.4], "v_b": 0.1}  # as written by hystkit before the move
    assert d == old and ladder.LadderParams.from_dict(old) == PARAMS3
    old_structure = {"n_cells": 3, "dt": DT, "slope_cap": 1.0}  # asdict(structure)
    assert STRUCT3.to_dict() == old_structure
    assert ladder.LadderStructure(**old_structure) == STRUCT3
    assert PARAMS3 != ladder.LadderParams.from_dict({**old, "v_b": 0.2})


@pytest.mark.parametrize("inverse", [False, True])
def test_analytical_linearisation_matches_numerical(inverse):
    run = FAMILY.invert_step if inverse else FAMILY.step
    for x, u in (([0.3, 0.05, -0.3], 0.7), ([0.1, 0.12, 0.0], 0.15), ([0.0, 0.4, 0.1], -0.5)):
        exact = FAMILY.linearise(STRUCT3, PARAMS3, x, u, inverse)
        approx = numerical_linearisation(lambda xx, uu: run(STRUCT3, PARAMS3, xx, uu),
                                         np.array(x), u)
        for e, a in zip(exact, approx):
            assert_allclose(e, a, rtol=1e-6, atol=1e-8)
