"""Least-squares identification (eq. 5.9): recovery of known parameters, failure reporting."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.errors import FitDivergedError
from hystkit.models import mpl
from hystkit.models.mpl import fit_mpl

DT = 0.025


def _input(n=8000):
    t = np.arange(n) * DT
    return np.sin(np.pi * t) * np.exp(-t / 100) + 0.2 * np.sin(2.3 * t)


@pytest.mark.parametrize("truth", [
    mpl.MplParams(i_s=[0.05], v_t=[0.3], w=[0.8, 0.4], v_b=0.1),
    # the document's initial conditions (paper 9.1) as the truth
    mpl.MplParams(i_s=[0.1], v_t=[0.2], w=[1.0, 0.4], v_b=-0.6),
    mpl.MplParams(i_s=[0.05, 0.2, 0.01], v_t=[0.3, 0.5, 0.1], w=[0.8, 0.4, -0.2, 0.3], v_b=0.1),
])
def test_recovers_known_parameters_from_noise_free_data(truth):
    structure = mpl.MplStructure(n_cells=truth.n_cells, dt=DT)
    u = _input()
    y, _ = mpl.simulate(structure, truth, u)
    result = fit_mpl(u, y, structure)
    assert result.converged
    assert result.cost < 1e-20
    # Cells are interchangeable: compare after sorting by time constant (rate G = 2 I_S / V_T).
    order_fit = np.argsort(2 * result.params.i_s / result.params.v_t)
    order_true = np.argsort(2 * truth.i_s / truth.v_t)
    # noise-free data and an exact Jacobian: the optimum is the truth to ~1e-9 relative
    assert_allclose(result.params.i_s[order_fit], truth.i_s[order_true], rtol=1e-7)
    assert_allclose(result.params.v_t[order_fit], truth.v_t[order_true], rtol=1e-7)
    assert_allclose(result.params.w[1:][order_fit], truth.w[1:][order_true], rtol=1e-7)
    assert_allclose(result.params.w[0], truth.w[0], rtol=1e-7)
    assert_allclose(result.params.v_b, truth.v_b, rtol=1e-7, atol=1e-9)


def test_noisy_data_gives_an_unbiased_fit():
    truth = mpl.MplParams(i_s=[0.05], v_t=[0.3], w=[0.8, 0.4], v_b=0.1)
    structure = mpl.MplStructure(n_cells=1, dt=DT)
    u = _input()
    y, _ = mpl.simulate(structure, truth, u)
    sigma = 0.01
    y_noisy = y + sigma * np.random.default_rng(3).standard_normal(y.size)
    result = fit_mpl(u, y_noisy, structure)
    # the residual is the noise: SSE / n ~ sigma^2 within a few per cent (chi-square, n = 8000)
    assert result.cost / u.size == pytest.approx(sigma**2, rel=0.05)
    assert_allclose(result.params.w, truth.w, rtol=0.02)


def test_acceptance_test_rejections_are_reported():
    structure = mpl.MplStructure(n_cells=1, dt=DT)
    u = _input(2000)
    with pytest.raises(FitDivergedError, match="rejected .because I said so."):
        fit_mpl(u, 0.5 * u, structure, accept=lambda p: False, accept_reason="because I said so")


def test_rejects_mismatched_or_non_finite_data():
    structure = mpl.MplStructure(n_cells=1, dt=DT)
    with pytest.raises(ValueError, match="equal length"):
        fit_mpl(np.zeros(10), np.zeros(9), structure)
    with pytest.raises(ValueError, match="finite"):
        fit_mpl(np.r_[np.zeros(9), np.nan], np.zeros(10), structure)
