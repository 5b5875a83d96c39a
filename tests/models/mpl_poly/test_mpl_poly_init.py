"""mpl-poly fitted from one given start (``init``; paper 9.2 started from table I)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.models import get_family
from hystkit.models.mpl_poly import fit as poly_fit
from hystkit.models.mpl_poly import model as poly

FAMILY = get_family("mpl-poly")
STRUCTURE = poly.MplPolyStructure(dt=0.025)
T = np.arange(3000) * 0.025
U = np.sin(2 * np.pi * 0.2 * T) * np.exp(-T / 80)


def test_table_i_start_is_used_exactly():
    table_i = FAMILY.presets()["paper-9.2-table-i"][1]
    y, _ = poly.simulate(STRUCTURE, FAMILY.presets()["table-ii-noise"][1], U)
    result = poly_fit.fit_mpl_poly(U, y, STRUCTURE, init=table_i, max_nfev=1, screen_nfev=1)
    assert result.n_starts == 1
    # one evaluation, no step: the start, in canonical form (the same input-output map)
    start_run, _ = poly.simulate(STRUCTURE, table_i, U)
    result_run, _ = poly.simulate(STRUCTURE, result.params, U)
    assert_allclose(result_run, start_run, rtol=1e-9, atol=1e-9)


def test_fit_from_table_i_matches_the_generating_model():
    y, _ = poly.simulate(STRUCTURE, FAMILY.presets()["table-ii-noise"][1], U)
    result = poly_fit.fit_mpl_poly(U, y, STRUCTURE,
                                   init=FAMILY.presets()["paper-9.2-table-i"][1])
    fitted, _ = poly.simulate(STRUCTURE, result.params, U)
    # noise-free data of the family itself: the residual is a small fraction of the signal
    assert np.sqrt(np.mean((fitted - y) ** 2)) < 1e-2 * np.std(y)


def test_start_options_clip_and_refuse_the_constraint():
    start = FAMILY.start_options(STRUCTURE, FAMILY.presets()["paper-9.2-table-i"][1])
    assert start.clipped == () and "init" in start.options
    assert "weight_sum_max" not in FAMILY.fit_options  # the gauge makes it restrict nothing
    with pytest.raises(ValueError, match="1 cell"):
        poly_fit.fit_mpl_poly(U, U, poly.MplPolyStructure(n_cells=2, dt=0.025),
                              init=FAMILY.presets()["paper-9.2-table-i"][1])
