"""The Power-Law fit names its two optimiser coordinates; both bounds are a search box."""

from dataclasses import replace

import numpy as np

from hystkit.compensation._diagnostics import bound_flags
from hystkit.models import pl
from hystkit.models.pl import fit_pl
from hystkit.models.pl.fit import THETA_NAMES

DT = 0.025


def test_a_threshold_on_its_bound_is_named():
    structure = pl.PlStructure(n_cells=2, power=5.0, n_basis=2, dt=DT)
    t = np.arange(800) * DT
    u = np.sin(1.3 * t) * np.exp(-t / 30)
    result = fit_pl(u, 0.8 * u + 0.1 * np.sin(1.3 * t - 0.4), structure, n_polish=1)
    assert result.names == THETA_NAMES == ("log_i_t", "log_v_t") and result.limits is None
    theta = np.array([result.bounds[0][0], result.bounds[1][1]])
    assert bound_flags(replace(result, theta=theta, sensitivity=None))[0] == [
        "log_i_t (lower)", "log_v_t (upper)"]
