"""The mPL fit's model limits (Euler slope cap, linear resistor) are notes, not bound failures;
search box hits are reported by parameter name."""

from dataclasses import replace

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.compensation._diagnostics import bound_flags, fit_status
from hystkit.models import mpl
from hystkit.models.mpl import fit_mpl
from hystkit.models.mpl.fit import theta_limits, theta_names

DT = 0.025
CAP = 1.0 / DT  # slope_cap 1 (the default) over dt


def _input(n=1500, seed=1):
    rng = np.random.default_rng(seed)
    u = np.convolve(rng.normal(size=n), np.ones(20) / 20, mode="same")
    return u / np.max(np.abs(u))  # normalised as the compensator does (eq. 5.10)


def _params(g, v_t, w=(0.7, 0.4), v_b=0.05):
    g, v_t = np.atleast_1d(g).astype(float), np.atleast_1d(v_t).astype(float)
    return mpl.MplParams(i_s=0.5 * g * v_t, v_t=v_t, w=list(w), v_b=v_b)


def test_past_a_model_limit_the_model_does_not_change():
    """The criterion for calling a bound a model limit, measured on the model itself."""
    structure = mpl.MplStructure(n_cells=1, dt=DT)
    u = 2.0 * _input()  # beyond the training range too
    at_cap = mpl.simulate(structure, _params(CAP, 0.3), u)[0]
    assert_array_equal(mpl.simulate(structure, _params(10 * CAP, 0.3), u)[0], at_cap)
    assert_array_equal(mpl.simulate(structure, _params(CAP, 0.01), u)[0], at_cap)
    v_t_bound = np.exp(mpl.box.LOG_VT_BOUNDS[1])
    at_bound = mpl.simulate(structure, _params(0.5, v_t_bound), u)[0]
    far = mpl.simulate(structure, _params(0.5, 1e9), u)[0]
    assert np.max(np.abs(at_bound - far)) < 1e-6 * np.ptp(far)
    # the other bounds are a search box: past them the output changes
    g_floor = np.exp(mpl.box.LOG_G_MIN)
    slower = mpl.simulate(structure, _params(g_floor / 100, 0.3), u)[0]
    assert np.max(np.abs(mpl.simulate(structure, _params(g_floor, 0.3), u)[0] - slower)) > 0


def test_a_cell_fitted_at_the_euler_cap_is_a_note_and_the_fit_is_ok():
    structure = mpl.MplStructure(n_cells=1, dt=DT)
    u = _input()
    y = mpl.simulate(structure, _params(10 * CAP, 0.3), u)[0]
    result = fit_mpl(u, y, structure)
    assert list(result.names) == theta_names(1)
    on_bounds, notes = bound_flags(result)
    assert on_bounds == []
    assert notes[0].startswith("cell 1 runs at the Euler slope cap")
    # V_T of a cell at the cap does not act on the output: wherever it ends, not a failure
    assert all("log_v_t[1] does not affect" in n for n in notes[1:])
    estimate = mpl.simulate(structure, result.params, u)[0]
    assert fit_status(estimate, y, 0.9 * y, on_bounds, True)[0] == "ok"


def test_a_linear_cell_resistor_is_a_note():
    structure = mpl.MplStructure(n_cells=1, dt=DT)
    u = _input()
    y = mpl.simulate(structure, _params(0.5, 1e6), u)[0]
    on_bounds, notes = bound_flags(fit_mpl(u, y, structure))
    assert on_bounds == []
    assert notes == [("cell 1 has a linear resistor (V_T at its bound 1000 stands for "
                      "V_T -> inf)")]


@pytest.mark.parametrize(("index", "side", "expected"), [
    (2, 1, "cell 2 runs at the Euler slope cap"),  # a model limit
    (3, 0, "log_v_t[2] (lower)"),
    (0, 0, "cell 1 integrates over the record"),  # G at its floor on a 15 s record
    (5, 1, "cell 3 has a linear resistor"),  # a model limit
    (7, 1, "w[1] (upper)"),
    (10, 0, "v_b (lower)"),
])
def test_constructed_three_cell_optimum_on_each_kind_of_bound(index, side, expected):
    """A fitted 3-cell result moved onto one bound: named search box hit or a cell's note."""
    structure = mpl.MplStructure(n_cells=3, dt=DT)
    u = _input(600)
    truth = _params([0.4, 2.0, 9.0], [0.3, 0.5, 0.2], w=(0.8, 0.4, -0.2, 0.3))
    result = fit_mpl(u, mpl.simulate(structure, truth, u)[0], structure, n_polish=1)
    assert bound_flags(result) == ([], [])  # the truth is inside every bound
    theta = result.theta.copy()
    theta[index] = result.bounds[side][index]
    moved = replace(result, theta=theta, sensitivity=None)
    on_bounds, notes = bound_flags(moved)
    label = theta_limits(3, True, u.size * DT)[side][index]
    if label is None:
        assert on_bounds == [expected] and notes == []
    else:
        assert on_bounds == [] and notes == [label] and label.startswith(expected)


def test_the_g_floor_is_a_search_box_on_a_record_long_enough_to_resolve_it():
    """At G = 1e-4 /s a cell moves by G T of its drive over a record of T seconds: over 15 s it
    integrates (only w G is identified); over 10^4 s it would move fully, so a fit at the
    floor there is a search box too small, reported as on bounds."""
    short, long = theta_limits(3, True, 15.0)[0][0], theta_limits(3, True, 1e4)[0][0]
    assert short.startswith("cell 1 integrates over the record") and "15 s of data" in short
    assert long is None
    assert theta_limits(3)[0][0] is None  # no record length known: a search box
