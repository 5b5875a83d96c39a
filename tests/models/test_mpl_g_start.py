"""mpl-g fitted from one given start (``init``) and under sum |w| <= B in its gauge."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.errors import FitDivergedError
from hystkit.models import get_family
from hystkit.models.mpl_g import fit as g_fit
from hystkit.models.mpl_g import model as mpl_g

FAMILY = get_family("mpl-g")
STRUCTURE = mpl_g.MplGStructure(dt=0.025)
T = np.arange(3000) * 0.025
U = np.sin(2 * np.pi * 0.2 * T) * np.exp(-T / 80)
TRUE = mpl_g.MplGParams(i_s=[0.3], v_t=[0.4], g=[0.05, 1.2, 0.02, 0.2], w=[1.0, -0.5])
# In the gauge g' = 1 + 0.15 (z - 0.1)^2 on |z| <= 2: Bernstein slopes 1.44, 0.39, 1.68, all
# positive, so the start lies inside the fit's monotone set
START = mpl_g.MplGParams(i_s=[0.1], v_t=[0.2], g=[0.0, 1.0, 0.0, 0.05], w=[1.0, 0.8],
                         v_b=-0.1)


@pytest.fixture(scope="module")
def y() -> np.ndarray:
    return mpl_g.simulate(STRUCTURE, TRUE, U)[0]


def test_start_is_used_exactly_in_the_gauge(y):
    result = g_fit.fit_mpl_g(U, y, STRUCTURE, init=START, max_nfev=1, screen_nfev=1)
    assert FAMILY.start_options(STRUCTURE, START).clipped == ()
    expected = g_fit.canonical(START)  # w_0 = 1, V_b = 0: the same model
    for name in ("i_s", "v_t", "g", "w"):
        assert_allclose(getattr(result.params, name), getattr(expected, name), rtol=1e-12,
                        atol=1e-12)


def test_non_monotone_start_is_reported_clipped():
    bent = mpl_g.MplGParams(i_s=[0.1], v_t=[0.2], g=[0.0, 1.0, 0.0, -0.2], w=[1.0, 0.4])
    notes = FAMILY.start_options(STRUCTURE, bent).clipped
    assert notes and all("g.log_slope" in note for note in notes)


def test_weight_sum_bound_is_active_and_costs_fit(y):
    free = g_fit.fit_mpl_g(U, y, STRUCTURE, init=START)
    bound = 1.3
    assert np.abs(free.params.w).sum() > bound + 0.1  # the premise: the bound must bite
    result = g_fit.fit_mpl_g(U, y, STRUCTURE, init=START, weight_sum_max=bound)
    assert_allclose(np.abs(result.params.w).sum(), bound, rtol=1e-8)
    assert result.cost > free.cost
    large = g_fit.fit_mpl_g(U, y, STRUCTURE, init=START, weight_sum_max=100.0)
    assert_allclose(large.cost, free.cost, rtol=1e-6, atol=1e-12)
    with pytest.raises(ValueError, match="at least 1"):
        g_fit.fit_mpl_g(U, y, STRUCTURE, weight_sum_max=0.5)


def test_linear_g_fallback_keeps_the_weight_sum_bound_or_fails(y):
    # accept vetoes every curved g, so the fit falls back on the mPL start with a linear g;
    # that start's sum |w| (gauge w_0 = 1) decides whether the bound is kept
    def linear_only(params):
        return np.allclose(params.g[2:], 0)

    fallback = g_fit.fit_mpl_g(U, y, STRUCTURE, accept=linear_only)
    weight_sum = np.abs(fallback.params.w).sum()
    assert weight_sum > 1.2  # the premise: a bound of 1.2 bites
    with pytest.raises(FitDivergedError, match="could not be carried out"):
        g_fit.fit_mpl_g(U, y, STRUCTURE, accept=linear_only, weight_sum_max=1.2)
    kept = g_fit.fit_mpl_g(U, y, STRUCTURE, accept=linear_only,
                           weight_sum_max=weight_sum + 0.1)
    assert_allclose(kept.params.w, fallback.params.w, rtol=0, atol=0)
    assert np.abs(kept.params.w).sum() <= weight_sum + 0.1
    assert "not solved under sum |w|" in kept.message
