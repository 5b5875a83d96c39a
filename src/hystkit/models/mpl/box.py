"""The mPL fit's box in optimiser coordinates (:meth:`MplParams.to_vector`) and the family's
documented domain, drawn from it (:func:`random_params`). Light: no optimiser is loaded, so the
family object reads it at import.
"""

from __future__ import annotations

import numpy as np

from .._docs import docfiller
from . import model as mpl

fill_doc = docfiller("MplStructure")

__all__ = ["LOG_G_MIN", "LOG_G_UNLIMITED", "LOG_VT_BOUNDS", "W_BOUND", "fit_box", "random_params",
           "theta_names"]

# Bounds in optimiser coordinates (see MplParams.to_vector). |w| <= 100 mirrors the document's
# weight-sum constraint of 10^2 (sec. 5.3.3).
LOG_VT_BOUNDS = (np.log(1e-3), np.log(1e3))
LOG_G_MIN = np.log(1e-4)
W_BOUND = 100.0
# Without the limit (limit=False) G has no Euler bound: a box wide enough for the document's
# fitted G = 2 I_S / V_T = 1.1e-5 (table 5.2) and inside the domain (I_S = G V_T / 2 within
# 1e-12 .. 1e12 for every V_T of the box).
LOG_G_UNLIMITED = (np.log(1e-8), np.log(1e8))


def theta_names(n_cells: int) -> list[str]:
    """Names of the optimiser coordinates (:meth:`MplParams.to_vector`), cells from 1."""
    cells = [f"{name}[{k}]" for k in range(1, n_cells + 1) for name in ("log_G", "log_v_t")]
    return [*cells, *(f"w[{k}]" for k in range(n_cells + 1)), "v_b"]


@fill_doc
def fit_box(structure: mpl.MplStructure) -> tuple[np.ndarray, np.ndarray]:
    """The fit's bounds in optimiser coordinates (:meth:`MplParams.to_vector`).

    ``log G_k`` in ``[log 1e-4, log(slope_cap / dt)]`` (the Euler limit) or, without the
    limit, ``[log 1e-8, log 1e8]``; ``log V_T,k`` in ``[log 1e-3, log 1e3]``; ``w_k`` and
    ``V_b`` in ``[-100, 100]``.

    %(structure_parameters)s

    Returns
    -------
    lower, upper : numpy.ndarray, shape (3N + 2,)
    """
    n = structure.n_cells
    if structure.limit:
        log_g = (LOG_G_MIN, np.log(structure.slope_cap / structure.dt))
    else:
        log_g = LOG_G_UNLIMITED
    lower = np.r_[np.tile([log_g[0], LOG_VT_BOUNDS[0]], n), np.full(n + 2, -W_BOUND)]
    upper = np.r_[np.tile([log_g[1], LOG_VT_BOUNDS[1]], n), np.full(n + 2, W_BOUND)]
    return lower, upper


def random_params(structure: mpl.MplStructure, rng: np.random.Generator) -> mpl.MplParams:
    """Parameters drawn from the fit's bounds (the family's documented domain): ``log G_k``
    and ``log V_T,k`` uniform between their bounds, ``w_0..w_N`` and ``V_b`` uniform in
    ``[-100, 100]`` (``V_b`` gets the weights' box; the fit leaves it free)."""
    n = structure.n_cells
    log_g = rng.uniform(LOG_G_MIN, np.log(structure.slope_cap / structure.dt), n)
    log_vt = rng.uniform(*LOG_VT_BOUNDS, n)
    lin = rng.uniform(-W_BOUND, W_BOUND, n + 2)
    return mpl.MplParams.from_vector(np.r_[np.column_stack([log_g, log_vt]).reshape(-1), lin], n)
