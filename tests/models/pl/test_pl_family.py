"""Power-Law model behind the family protocol: loop blocks, inverse step, rest states, at(dt),
records, analytical linearisation."""

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.models import get_family, numerical_linearisation, pl

DT = 0.025
FAMILY = get_family("pl")
STRUCT = pl.PlStructure(n_cells=3, power=21.0, n_basis=4, dt=DT)
PARAMS = pl.PlParams(i_t=0.5, v_t=0.2, w=[0.8, 0.3, 0.5, -0.2], v_b=0.1, a=[0.5, 2.0, 1.0, 3.0])
# p = 5 with a large I_T: the power law hands over to the straight branch below the threshold
STEEP = pl.PlStructure(n_cells=2, power=5.0, n_basis=3, dt=DT)
STEEP_PARAMS = pl.PlParams(i_t=40.0, v_t=0.3, w=[0.7, 0.4, -0.5], v_b=-0.05, a=[1.5, 0.6, 0.9])
CASES = [(STRUCT, PARAMS), (STEEP, STEEP_PARAMS)]


@pytest.mark.parametrize("structure, params", CASES)
def test_blocks_equal_step_and_invert_step_from_a_non_rest_state(structure, params, drive):
    rng = np.random.default_rng(4)
    u = 1.3 * np.convolve(rng.standard_normal(400), np.ones(3) / 3, "same")
    x0 = rng.uniform(-0.8, 0.8, structure.n_cells)
    y_blk, x_blk = drive(FAMILY.block(structure, params, False), x0, u, off=2)
    y_ref, x_ref = drive(lambda x, v: FAMILY.step(structure, params, x, v), x0, u)
    # pow rounding; f^-1 walks the segments in another order than the reference
    assert_allclose(y_blk, y_ref, rtol=0, atol=1e-12)
    assert_allclose(x_blk, x_ref, rtol=0, atol=1e-12)
    # the output spans several segments of f, the cells both branches
    assert np.ptp(np.searchsorted(pl.basis_breakpoints(params.n_basis)[1:-1], y_ref)) >= 2
    e_blk, xi_blk = drive(FAMILY.block(structure, params, True), x0, y_ref, off=2)
    e_ref, xi_ref = drive(lambda x, v: FAMILY.invert_step(structure, params, x, v), x0, y_ref)
    assert_allclose(e_blk, e_ref, rtol=0, atol=1e-12)
    assert_allclose(xi_blk, xi_ref, rtol=0, atol=1e-12)
    assert_allclose(e_ref, u, rtol=0, atol=1e-11)  # same start: the inverse undoes the model


def test_invert_step_is_the_readable_reference_of_invert(drive):
    y, _ = pl.simulate(STRUCT, PARAMS, np.sin(np.arange(500) * 0.03))
    x0 = np.array([0.2, -0.1, 0.4])
    e, x_end = pl.invert(STRUCT, PARAMS, y, x0=x0)
    e_ref, x_ref = drive(lambda x, v: pl.invert_step(STRUCT, PARAMS, x, v), x0, y)
    assert_allclose(e, e_ref, rtol=0, atol=1e-13)
    assert_allclose(x_end, x_ref[-1], rtol=0, atol=1e-14)


def test_inverse_block_refuses_w0_zero():
    p = pl.PlParams(i_t=0.5, v_t=0.2, w=[0.0, 0.3, 0.5, -0.2], a=PARAMS.a)
    FAMILY.block(STRUCT, p)
    with pytest.raises(Exception, match="w_0 = 0"):
        FAMILY.block(STRUCT, p, inverse=True)


@pytest.mark.parametrize("value", [-0.9, 0.0, 0.4])
def test_rest_state_is_a_fixed_point_and_where_runs_start(value):
    for inverse, run, whole in ((False, FAMILY.step, FAMILY.simulate),
                                (True, FAMILY.invert_step, FAMILY.invert)):
        x = FAMILY.rest_state(STRUCT, PARAMS, value, inverse=inverse)
        out, x_next = run(STRUCT, PARAMS, x, value)
        assert_allclose(x_next, x, rtol=0, atol=1e-15)
        out_run, x_end = whole(STRUCT, PARAMS, np.full(3, value))
        assert_allclose(out_run, out, rtol=0, atol=1e-15)
        assert_allclose(x_end, x, rtol=0, atol=1e-15)
    # at inverse rest the estimate is the source at which the model gives this output
    e = FAMILY.invert_step(STRUCT, PARAMS, FAMILY.rest_state(STRUCT, PARAMS, value, True),
                           value)[0]
    y, _ = FAMILY.step(STRUCT, PARAMS, FAMILY.rest_state(STRUCT, PARAMS, e), e)
    assert y == pytest.approx(value, abs=1e-13)


def test_at_keeps_the_cells_and_moves_the_straight_branch_with_dt():
    fine = FAMILY.at(STEEP, DT / 5)
    assert fine == pl.PlStructure(n_cells=2, power=5.0, n_basis=3, smoothing=0.001,
                                  dt=DT / 5, slope_cap=1.0)
    # G dt stays the cap: the slope of the straight branch is slope_cap / dt at any dt
    far = np.array([[2.0, 2.0], [2.5, 2.5]])
    for s in (STEEP, fine):
        d = pl.resistor_current(s, STEEP_PARAMS, far)
        assert_allclose((d[1] - d[0]) / 0.5, s.slope_cap / s.dt, rtol=1e-12)
    # inside the thresholds the power law is the same ODE: creep after a small step converges
    # at first order in dt (slow cells, no straight branch reached)
    slow = pl.PlStructure(n_cells=2, power=5.0, dt=DT)
    p = pl.PlParams(i_t=0.5, v_t=0.3, w=[0.0, 1.0, 1.0])
    t_end, errors = 2.0, []
    ref, _ = FAMILY.simulate(FAMILY.at(slow, DT / 64), p, np.full(int(t_end / (DT / 64)), 0.25),
                             x0=0.0)
    for k in (2, 4, 8):
        y, _ = FAMILY.simulate(FAMILY.at(slow, DT / k), p, np.full(int(t_end / (DT / k)), 0.25),
                               x0=0.0)
        errors.append(np.max(np.abs(y - ref[::64 // k])))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 1.6) & (ratios < 2.6)), ratios


def test_records_round_trip_and_old_model_file_keys_load():
    assert pl.PlParams.from_dict(json.loads(json.dumps(PARAMS.to_dict()))) == PARAMS
    assert pl.PlStructure.from_dict(json.loads(json.dumps(STRUCT.to_dict()))) == STRUCT
    # keys as the previous version wrote them (explicit to_dict / dataclasses.asdict)
    old_params = {"i_t": 0.5, "v_t": 0.2, "w": [0.8, 0.3, 0.5, -0.2], "v_b": 0.1,
                  "a": [0.5, 2.0, 1.0, 3.0]}
    old_structure = {"n_cells": 3, "power": 21.0, "n_basis": 4, "smoothing": 0.001,
                     "dt": 0.025, "slope_cap": 1.0}
    assert PARAMS.to_dict() == old_params
    assert STRUCT.to_dict() == old_structure
    assert pl.PlParams.from_dict(old_params) == PARAMS
    assert FAMILY.Structure(**old_structure) == STRUCT
    assert PARAMS != pl.PlParams.from_dict({**old_params, "a": [0.5, 2.0, 1.0, 3.5]})
    assert FAMILY.n_params(STRUCT, PARAMS) == STRUCT.n_params


@pytest.mark.parametrize("inverse", [False, True])
@pytest.mark.parametrize("structure, params", CASES)
def test_analytical_linearisation_matches_numerical(structure, params, inverse):
    rng = np.random.default_rng(6)
    run = FAMILY.invert_step if inverse else FAMILY.step
    _, knee, _ = pl.kernel_args(structure, params)[1:4]
    brk = pl.basis_breakpoints(params.n_basis)[1:-1]
    checked = 0
    for _ in range(30):
        x, u = rng.uniform(-0.7, 0.7, structure.n_cells), rng.uniform(-0.9, 0.9)
        y, _ = run(structure, params, x, u)
        drive = y if inverse else u
        i = u if inverse else y
        if (np.min(np.abs(np.abs(drive - x) - knee)) < 1e-3
                or np.min(np.abs(i - brk)) < 1e-3):
            continue  # on a kink the numerical derivative averages two slopes
        lin = FAMILY.linearise(structure, params, x, u, inverse=inverse)
        num = numerical_linearisation(lambda xx, uu: run(structure, params, xx, uu), x, u)
        for mine, ref in zip(lin, num, strict=True):
            assert_allclose(mine, ref, rtol=1e-5, atol=1e-7)
        checked += 1
    assert checked >= 15
