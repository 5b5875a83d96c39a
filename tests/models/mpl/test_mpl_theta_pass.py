"""The fit's pass at optimiser coordinates (``kernels.theta_normal_equations``) hands
``normal_equations`` arguments of the same numba types as the fit's linear start does, so a cold
fit compiles that pass once (issue 29.3), and it is the pass of those arguments bit for bit."""

import numba
import numpy as np
import pytest

from hystkit.models import mpl
from hystkit.models.mpl import fit as mpl_fit
from hystkit.models.mpl import kernels


def _linear_start_types(structure, params, u):
    """numba types of the arguments ``fit._linear_init`` passes to ``normal_equations``."""
    knee = mpl.knee_voltage(structure, params)
    args = (u, u, np.full(structure.n_cells, u[0]), params.i_s, params.v_t, params.w, 0.0, knee,
            structure.slope_cap / structure.dt, structure.dt)
    return tuple(numba.typeof(a) for a in args)


@pytest.mark.parametrize("n_cells", [1, 3])
def test_theta_pass_uses_the_linear_starts_specialisation(n_cells, monkeypatch):
    structure = mpl.MplStructure(n_cells=n_cells, dt=0.025)
    rng = np.random.default_rng(n_cells)
    params = mpl_fit.random_params(structure, rng)
    u = np.cumsum(rng.normal(size=300)) * 0.05
    theta = params.to_vector()
    seen = []
    real = kernels.normal_equations
    monkeypatch.setattr(kernels, "normal_equations", lambda *a: seen.append(a) or real(*a))
    result = kernels.theta_normal_equations(u, u, np.full(n_cells, u[0]), theta,
                                            structure.slope_cap, structure.dt)
    (args,) = seen
    assert tuple(numba.typeof(a) for a in args) == _linear_start_types(structure, params, u)
    assert theta.flags.writeable  # only views of it were made read-only
    for got, want in zip(result, real(*args)):
        assert np.array_equal(got, want)


def test_a_read_only_argument_type_differs_from_a_writeable_one():
    """The premise: numba compiles a writeable and a read-only array separately."""
    ro = np.zeros(3)
    ro.flags.writeable = False
    assert numba.typeof(ro) != numba.typeof(np.zeros(3))
