"""The polynomial mPL fit names its optimiser coordinates; it has no model-limit bounds."""

from dataclasses import replace

import numpy as np

from hystkit.compensation._diagnostics import bound_flags
from hystkit.models import mpl_poly as mp
from hystkit.models.mpl_poly import fit_mpl_poly
from hystkit.models.mpl_poly.fit import theta_names

DT = 0.025


def test_a_coefficient_on_its_bound_is_named():
    structure = mp.MplPolyStructure(n_cells=2, dt=DT)
    t = np.arange(800) * DT
    u = np.sin(1.3 * t) * np.exp(-t / 30)
    result = fit_mpl_poly(u, 0.8 * u + 0.1 * np.sin(1.3 * t - 0.4), structure, n_polish=1)
    names = theta_names(2)
    assert list(result.names) == names and len(names) == result.theta.size == 5 * 2 + 6
    assert result.limits is None  # the Euler cap acts through the knees, not a bound
    before = bound_flags(replace(result, sensitivity=None))[0]
    assert all(hit.split(" ")[0] in names for hit in before)
    theta = result.theta.copy()
    j = names.index("f[2].log_c3")
    theta[j] = result.bounds[1][j]
    after = bound_flags(replace(result, theta=theta, sensitivity=None))[0]
    assert set(after) - set(before) == {"f[2].log_c3 (upper)"}
