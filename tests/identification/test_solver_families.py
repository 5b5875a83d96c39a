"""Every family's default fit (trust-region reflective on normal equations) reaches the cost
of the scipy ``trf`` path on the same data.

Tolerance: the default solver takes trf's steps, computed from J^T J instead of J, so the paths
agree up to rounding and the final SSEs to the accuracy of the stopping rules on a shared
optimum (ftol = 1e-8 relative decrease); 1e-4 relative leaves room for a flat valley where
rounding moves the stopping point, while a different local minimum changes the SSE by per cents.
"""

import numpy as np
import pytest

from hystkit.compensation import centre_and_scale
from hystkit.models import boucwen, chua, ladder, mpl, mpl_poly, pl
from hystkit.sensors._virtual import simulate_experiment

RTOL = 1e-4


@pytest.fixture(scope="module")
def sine_data():
    """The virtual sensor's sine recording (seed 1), direct mode, first 2000 samples."""
    rec = simulate_experiment("sine", 1)
    _, u, y = centre_and_scale(rec, "recording")
    return u[:2000].copy(), y[:2000].copy(), rec.dt


def _same_cost(fit, *args, **kwargs):
    new = fit(*args, **kwargs)
    old = fit(*args, solver="trf", **kwargs)
    assert new.converged, new.message
    assert new.cost == pytest.approx(old.cost, rel=RTOL)
    return new, old


@pytest.mark.parametrize("n_cells", [1, 2, 3])
def test_mpl(sine_data, n_cells):
    u, y, dt = sine_data
    _same_cost(mpl.fit_mpl, u, y, mpl.MplStructure(n_cells=n_cells, dt=dt))


@pytest.mark.parametrize("limit", [True, False])
def test_mpl_poly(sine_data, limit):
    u, y, dt = sine_data
    _same_cost(mpl_poly.fit_mpl_poly, u, y, mpl_poly.MplPolyStructure(n_cells=1, dt=dt,
                                                                      limit=limit))


def test_chua(sine_data):
    u, y, dt = sine_data
    _same_cost(chua.fit_chua, u, y, chua.ChuaStructure(n_elements=1, dt=dt))


def test_pl(sine_data):
    u, y, dt = sine_data
    _same_cost(pl.fit_pl, u, y, pl.PlStructure(n_cells=2, power=5.0, n_basis=3, smoothing=0.0,
                                               dt=dt))


def test_ladder(sine_data):
    """ladder keeps trf as its default (see fit_ladder); "tr" must still reach its cost."""
    u, y, dt = sine_data
    structure = ladder.LadderStructure(n_cells=2, dt=dt)
    new = ladder.fit_ladder(u, y, structure, solver="tr")
    old = ladder.fit_ladder(u, y, structure)
    assert new.converged, new.message
    assert new.cost == pytest.approx(old.cost, rel=RTOL)


def test_boucwen():
    """A force-displacement record of a known oscillator with 1 % output noise."""
    dt, n = 0.025, 1200
    t = np.arange(n) * dt
    u = (0.8 * np.sin(2 * np.pi * 0.3 * t) + 0.4 * np.sin(2 * np.pi * 0.7 * t + 1)
         + 0.3 * np.sin(2 * np.pi * 1.3 * t + 2))
    structure = boucwen.BoucWenStructure(dt=dt, substeps=2, start="equilibrium")
    truth = boucwen.BoucWenParams(m=0.002, c=0.01, k=0.6, alpha=0.8, beta=0.5, gamma=-0.8,
                                  nu=1.5)
    y, _ = boucwen.simulate(structure, truth, u)
    y = y + 0.01 * np.max(np.abs(y)) * np.random.default_rng(0).normal(size=y.size)
    _same_cost(boucwen.fit_boucwen, u, y, structure)
