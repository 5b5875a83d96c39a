"""Polynomial mPL behind the family protocol: loop blocks, rest states, at(dt), records,
analytical linearisation."""

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.models import get_family, numerical_linearisation
from hystkit.models import mpl_poly as mp

DT = 0.025
FAMILY = get_family("mpl-poly")
STRUCT2 = mp.MplPolyStructure(n_cells=2, dt=DT)
# cell 2 is steep (knees at about +-0.2): runs visit the straight continuations of eq. 5.29
PARAMS2 = mp.MplPolyParams(f=[[0.05, 1.5, 0.4, 2.0], [-0.1, 8.0, 1.0, 300.0]],
                           g=[0.02, 0.9, 0.05, 0.1], w=[1.2, -0.4, -0.3], v_b=0.03)
# g(z) = z - z^3 / 3: monotone on [-1, 1] only, range [-2/3, 2/3]
BOUNDED = mp.MplPolyParams(f=[[0.0, 1.0, 0.0, 1.0]], g=[0.0, 1.0, 0.0, -1 / 3], w=[1.0, 0.5])
STRUCT1 = mp.MplPolyStructure(n_cells=1, dt=DT)


def test_forward_block_equals_step_from_a_non_rest_state(drive):
    rng = np.random.default_rng(1)
    u = 1.5 * rng.standard_normal(400)
    x0 = np.array([0.7, -0.9])  # far from rest: the steep cell starts on its straight line
    y_blk, x_blk = drive(FAMILY.block(STRUCT2, PARAMS2, False), x0, u, off=3)
    y_ref, x_ref = drive(lambda x, v: FAMILY.step(STRUCT2, PARAMS2, x, v), x0, u)
    assert_allclose(y_blk, y_ref, rtol=0, atol=1e-12)
    assert_allclose(x_blk, x_ref, rtol=0, atol=1e-12)
    knees = mp.knee_points(STRUCT2, PARAMS2)[1]
    v = u - np.r_[x0[1], x_ref[:-1, 1]]
    assert np.sum((v <= knees[0]) | (v >= knees[1])) > 50  # the limit is exercised


def test_inverse_block_equals_invert_step_from_a_non_rest_state(drive):
    rng = np.random.default_rng(2)
    y = np.convolve(rng.standard_normal(400), np.ones(5) / 5, "same")
    x0 = np.array([0.4, -0.6])
    u_blk, x_blk = drive(FAMILY.block(STRUCT2, PARAMS2, True), x0, y, off=3)
    u_ref, x_ref = drive(lambda x, v: FAMILY.invert_step(STRUCT2, PARAMS2, x, v), x0, y)
    assert np.all(np.isfinite(u_ref))
    # Newton (block) vs brentq (invert_step), both to ~1 ulp of z
    assert_allclose(u_blk, u_ref, rtol=0, atol=1e-12)
    assert_allclose(x_blk, x_ref, rtol=0, atol=1e-12)


def test_inverse_outside_the_branch_is_nan_in_block_and_step(drive):
    y = np.array([0.1, 0.5, 0.7, 0.2])  # 0.7 > 2/3: no input gives it
    u_blk, x_blk = drive(FAMILY.block(STRUCT1, BOUNDED, True), [0.1], y, off=3)
    u_ref, x_ref = drive(lambda x, v: FAMILY.invert_step(STRUCT1, BOUNDED, x, v), [0.1], y)
    assert_allclose(u_blk[:2], u_ref[:2], rtol=0, atol=1e-12)
    assert np.isnan(u_blk[2]) and np.isnan(u_ref[2])
    assert np.all(np.isnan(x_blk[2:])) and np.all(np.isnan(x_ref[2:]))


def test_inverse_block_refuses_w0_zero():
    p = mp.MplPolyParams(f=PARAMS2.f, g=PARAMS2.g, w=[0.0, -0.4, -0.3])
    FAMILY.block(STRUCT2, p)  # the forward model is fine
    with pytest.raises(Exception, match="w_0 = 0"):
        FAMILY.block(STRUCT2, p, inverse=True)


@pytest.mark.parametrize("value", [-0.8, 0.0, 0.35])
def test_rest_state_is_a_fixed_point_and_where_runs_start(value):
    for inverse, run, whole in ((False, FAMILY.step, FAMILY.simulate),
                                (True, FAMILY.invert_step, FAMILY.invert)):
        x = FAMILY.rest_state(STRUCT2, PARAMS2, value, inverse=inverse)
        out, x_next = run(STRUCT2, PARAMS2, x, value)
        assert_allclose(x_next, x, rtol=0, atol=1e-12)
        # simulate / invert with x0=None start there: same first sample and end state
        out_run, x_end = whole(STRUCT2, PARAMS2, np.full(3, value))
        assert_allclose(out_run, out, rtol=0, atol=1e-12)
        assert_allclose(x_end, x, rtol=0, atol=1e-12)
    # inverse at rest: the estimate is the input that rests at this output
    e = FAMILY.invert_step(STRUCT2, PARAMS2, FAMILY.rest_state(STRUCT2, PARAMS2, value, True),
                           value)[0]
    y, _ = FAMILY.step(STRUCT2, PARAMS2, FAMILY.rest_state(STRUCT2, PARAMS2, e), e)
    assert y == pytest.approx(value, abs=1e-12)


def test_at_keeps_the_ode_and_moves_the_knees_with_dt():
    fine = FAMILY.at(STRUCT2, DT / 4)
    assert fine == mp.MplPolyStructure(n_cells=2, dt=DT / 4, slope_cap=1.0, limit=True)
    assert FAMILY.at(mp.MplPolyStructure(limit=False, slope_cap=0.5), 0.01) == \
        mp.MplPolyStructure(dt=0.01, slope_cap=0.5, limit=False)
    # the knees solve f'(x) = slope_cap / dt at the new step
    c = PARAMS2.f[1]
    knees = mp.knee_points(fine, PARAMS2)[1]
    assert_allclose(c[1] + 2 * c[2] * knees + 3 * c[3] * knees**2, 4 / DT, rtol=1e-12)
    # same ODE: forward Euler converges at first order as dt shrinks (smooth input, 2 s)
    t_ref = np.arange(0, 2, DT / 64)
    u_ref = np.sin(2 * np.pi * t_ref) * 0.3
    y_ref, _ = FAMILY.simulate(FAMILY.at(STRUCT2, DT / 64), PARAMS2, u_ref)
    errors = []
    for k in (4, 8, 16):
        y, _ = FAMILY.simulate(FAMILY.at(STRUCT2, DT / k), PARAMS2, u_ref[::64 // k])
        errors.append(np.max(np.abs(y - y_ref[::64 // k])))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 1.6) & (ratios < 2.6)), ratios


def test_records_round_trip_and_old_model_file_keys_load():
    d = json.loads(json.dumps(PARAMS2.to_dict()))
    assert mp.MplPolyParams.from_dict(d) == PARAMS2
    assert mp.MplPolyStructure.from_dict(json.loads(json.dumps(STRUCT2.to_dict()))) == STRUCT2
    # keys as the previous version wrote them (explicit to_dict / dataclasses.asdict)
    old_params = {"f": [[0.05, 1.5, 0.4, 2.0], [-0.1, 8.0, 1.0, 300.0]],
                  "g": [0.02, 0.9, 0.05, 0.1], "w": [1.2, -0.4, -0.3], "v_b": 0.03}
    old_structure = {"n_cells": 2, "dt": 0.025, "slope_cap": 1.0, "limit": True}
    assert PARAMS2.to_dict() == old_params
    assert STRUCT2.to_dict() == old_structure
    assert mp.MplPolyParams.from_dict(old_params) == PARAMS2
    assert FAMILY.Structure(**old_structure) == STRUCT2
    assert PARAMS2 != mp.MplPolyParams.from_dict({**old_params, "v_b": 0.04})
    # 5N + 6 stored numbers, of which c_k0, w_0 and V_b are the fit's gauge (issue 25.3)
    assert FAMILY.n_params(STRUCT2, PARAMS2) == STRUCT2.n_params - (STRUCT2.n_cells + 2) == 12


@pytest.mark.parametrize("inverse", [False, True])
def test_analytical_linearisation_matches_numerical(inverse):
    rng = np.random.default_rng(5)
    run = FAMILY.invert_step if inverse else FAMILY.step
    checked = 0
    for _ in range(20):
        x, u = rng.uniform(-0.6, 0.6, 2), rng.uniform(-0.8, 0.8)
        drive = run(STRUCT2, PARAMS2, x, u)[0] if inverse else u
        knees = mp.knee_points(STRUCT2, PARAMS2)
        if np.any(np.min(np.abs(drive - x - knees.T), axis=0) < 1e-3):
            continue  # on a kink the numerical derivative averages two slopes
        a, b, c, d = FAMILY.linearise(STRUCT2, PARAMS2, x, u, inverse=inverse)
        na, nb, nc, nd = numerical_linearisation(
            lambda xx, uu: run(STRUCT2, PARAMS2, xx, uu), x, u)
        for mine, num in ((a, na), (b, nb), (c, nc), (d, nd)):
            assert_allclose(mine, num, rtol=1e-6, atol=1e-7)
        checked += 1
    assert checked >= 10


def test_presets_are_paper_9_2_table_ii_and_run():
    presets = FAMILY.presets()
    assert sorted(presets) == sorted([*(f"table-ii-{c}" for c in mp.PAPER_9_2_TABLE_II),
                                      "paper-9.2-table-i"])
    assert presets.pop("paper-9.2-table-i")[1] == mp.paper_9_2_params(mp.PAPER_9_2_TABLE_I)
    for name, (structure, params, info) in presets.items():
        column = name.removeprefix("table-ii-")
        assert params == mp.paper_9_2_params(mp.PAPER_9_2_TABLE_II[column])
        assert "paper 9.2" in info["source"]
        y, _ = FAMILY.simulate(structure, params, 0.8 * np.sin(np.arange(400) * 0.05))
        assert np.all(np.isfinite(y))
