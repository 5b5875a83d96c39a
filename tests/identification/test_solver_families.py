"""Every family's default fit (trust-region reflective on normal equations) reaches the cost
of the scipy ``trf`` path on the same data.

Tolerance: the default solver takes trf's steps, computed from J^T J instead of J, so the paths
agree up to rounding and the final SSEs to the accuracy of the stopping rules on a shared
optimum (ftol = 1e-8 relative decrease); 1e-4 relative leaves room for a flat valley where
rounding moves the stopping point, while a different local minimum changes the SSE by per cents.
"""

import pytest

from hystkit.compensation import centre_and_scale
from hystkit.models import mpl, mpl_poly
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
