"""The mPL fit with the weights projected out (projection.Projection, issue 29.5): its normal
equations are the full problem's at the best weights, and the 1-cell fit it drives reaches the
full search's minimum."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.compensation import centre_and_scale
from hystkit.identification import NormalEquations
from hystkit.models import mpl
from hystkit.models.mpl import fit as mpl_fit
from hystkit.models.mpl import kernels
from hystkit.models.mpl.projection import COST_SCALE, Projection
from hystkit.sensors._virtual import simulate_experiment

DT = 0.025


def _data(n_cells, n=3000):
    t = np.arange(n) * DT
    u = np.sin(np.pi * t) * np.exp(-t / 100) + 0.2 * np.sin(2.3 * t)
    truth = mpl.MplParams(i_s=[0.05, 0.2, 0.01][:n_cells], v_t=[0.3, 0.5, 0.1][:n_cells],
                          w=[0.8, 0.4, -0.2, 0.3][: n_cells + 1], v_b=0.1)
    structure = mpl.MplStructure(n_cells=n_cells, dt=DT)
    y = mpl.simulate(structure, truth, u)[0]
    y = y + 0.01 * np.random.default_rng(1).standard_normal(n)
    return structure, u, y


def _unscaled(ne):
    return NormalEquations(*(part / COST_SCALE for part in (ne.cost, ne.jtj, ne.jtr)))


def _full_problem(structure, u, y):
    def normal_equations(theta):
        sse, jtj, jtr = kernels.theta_normal_equations(u, y, np.full(structure.n_cells, u[0]),
                                                       theta, structure.slope_cap, structure.dt)
        return NormalEquations(0.5 * sse, jtj, jtr)
    return normal_equations


@pytest.mark.parametrize("n_cells", [1, 2])
def test_projected_normal_equations_are_the_full_ones_at_the_best_weights(n_cells):
    structure, u, y = _data(n_cells)
    full = _full_problem(structure, u, y)
    lower, upper = mpl_fit.fit_box(structure)
    m = 2 * n_cells
    projected = Projection(full, n_cells, lower[m:], upper[m:])
    cells = np.log([0.4, 0.5, 0.9, 0.3][:m])  # (log G, log V_T) per cell, away from the truth
    reduced = _unscaled(projected(cells))
    at = full(projected.full(cells))
    assert reduced.cost == pytest.approx(at.cost, rel=1e-9)
    scale = np.sqrt(np.diag(at.jtj))
    # the weights are optimal: no gradient left along them (relative to the column norms)
    assert np.all(np.abs(at.jtr[m:]) <= 1e-8 * scale[m:] * np.sqrt(2 * at.cost))
    assert_allclose(reduced.jtr, at.jtr[:m], rtol=1e-7, atol=1e-9 * np.abs(at.jtr[:m]).max())
    schur = at.jtj[:m, :m] - at.jtj[:m, m:] @ np.linalg.solve(at.jtj[m:, m:], at.jtj[m:, :m])
    assert_allclose(reduced.jtj, schur, rtol=1e-6, atol=1e-9 * np.abs(schur).max())
    # a point the solver never evaluated (as after a worker's solve) is run once more
    calls = []
    projected = Projection(lambda theta: calls.append(theta) or full(theta), n_cells,
                           lower[m:], upper[m:])
    projected(cells)
    projected.full(cells)
    assert len(calls) == 1
    assert_allclose(projected.full(cells + 0.1)[:m], cells + 0.1)
    assert len(calls) == 2


def test_weights_held_in_their_box_keep_the_cost_and_free_gradient_consistent():
    structure, u, y = _data(1)
    full = _full_problem(structure, u, y)
    # a box the unconstrained best weights leave (w_1 near 0.4 there): |w| <= 0.2
    low, high = np.full(3, -0.2), np.full(3, 0.2)
    projected = Projection(full, 1, low, high)
    cells = np.log([0.4, 0.3])
    reduced = _unscaled(projected(cells))
    theta = projected.full(cells)
    assert np.all((theta[2:] >= low) & (theta[2:] <= high))
    assert np.any(np.isclose(np.abs(theta[2:]), 0.2))
    at = full(theta)
    assert reduced.cost == pytest.approx(at.cost, rel=1e-9)
    free = np.abs(theta[2:]) < 0.2 - 1e-12
    scale = np.sqrt(np.diag(at.jtj))
    assert np.all(np.abs(at.jtr[2:][free]) <= 1e-8 * scale[2:][free] * np.sqrt(2 * at.cost))
    assert_allclose(reduced.jtr, at.jtr[:2], rtol=1e-7)


def test_one_cell_fit_reaches_the_full_search_minimum_in_fewer_runs(monkeypatch):
    rec = simulate_experiment("sine", 2)
    _, u, y = centre_and_scale(rec, "recording")
    structure = mpl.MplStructure(n_cells=1, dt=rec.dt)
    projected = mpl_fit.fit_mpl(u, y, structure)
    monkeypatch.setattr(mpl_fit, "PROJECTED_CELLS", 0)  # the full search, as for more cells
    full = mpl_fit.fit_mpl(u, y, structure)
    assert projected.converged and full.converged
    assert projected.cost <= full.cost * (1 + 1e-9)
    assert projected.cost == pytest.approx(full.cost, rel=1e-6)  # the same minimum
    assert projected.n_evaluations < 0.8 * full.n_evaluations
    assert projected.n_starts == full.n_starts == len(mpl_fit.default_starts(structure))


def test_two_recordings_end_to_end_reach_the_full_search_minimum(monkeypatch):
    """The sine (seed 1) and decay (seed 2) runs fitted end to end: with one polish the best
    screened start ended at a linear cell on the V_T bound, SSE 15 % above the full search's
    minimum (PROJECTED_POLISH = 1); the second-best start, polished too, reaches it."""
    from hystkit.compensation import fit_compensator

    recs = [simulate_experiment("sine", 1), simulate_experiment("decay", 2)]
    projected = fit_compensator(recs, 1, diagnose=False)
    monkeypatch.setattr(mpl_fit, "PROJECTED_CELLS", 0)
    full = fit_compensator(recs, 1, diagnose=False)
    assert projected.fit_info["cost"] == pytest.approx(full.fit_info["cost"], rel=1e-6)
    assert projected.params.v_t[0] < 1.0  # a hysteretic cell, not the linear one at the bound


def test_a_near_exact_fit_gets_its_cost_from_a_pass_at_its_own_weights():
    """Noise-free data near the truth: the probe's cost minus the projection would lose the
    digits of a cost ~1e-9 of it; a second pass at the best weights keeps them."""
    structure, u, _ = _data(1)
    truth = mpl.MplParams(i_s=[0.05], v_t=[0.3], w=[0.8, 0.4], v_b=0.1)
    y = mpl.simulate(structure, truth, u)[0]
    full = _full_problem(structure, u, y)
    lower, upper = mpl_fit.fit_box(structure)
    calls = []
    projected = Projection(lambda theta: calls.append(theta) or full(theta), 1, lower[2:],
                           upper[2:])
    cells = truth.to_vector()[:2] + 1e-5
    reduced = _unscaled(projected(cells))
    assert len(calls) == 2  # the second pass, at the best weights
    at = full(projected.full(cells))
    assert 0 < at.cost < 1e-9
    assert reduced.cost == pytest.approx(at.cost, rel=1e-6)
    assert_allclose(reduced.jtr, at.jtr[:2], rtol=1e-6)
