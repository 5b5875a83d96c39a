"""The Power-Law fit's box and the family's documented domain drawn from it (:func:`random_params`);
light (no optimiser loaded), so the family object reads it at import.
"""

from __future__ import annotations

import numpy as np

from . import model as pl

__all__ = ["A_MIN", "LOG_IT", "LOG_VT", "W_BOUND", "random_params"]


W_BOUND = 100.0
A_MIN = 0.05
LOG_VT = (np.log(1e-3), np.log(2.0))  # thresholds beyond N * 2 never matter on [-1, 1] data
LOG_IT = (np.log(1e-6), np.log(1e4))


def random_params(structure: pl.PlStructure, rng: np.random.Generator) -> pl.PlParams:
    """Parameters drawn from the fit's bounds (the family's documented domain): ``log I_T``,
    ``log V_T`` uniform between their bounds (``I_T`` in ``[1e-6, 1e4]``, ``V_T`` in
    ``[1e-3, 2]``), ``w_0..w_N`` uniform in ``[-100, 100]``, ``V_b`` too (the fit leaves it
    free), and slopes ``a_j >= 0.05`` with the fit's scale ``sum a_j = M``."""
    n, m = structure.n_cells, structure.n_basis
    i_t, v_t = np.exp(rng.uniform(*LOG_IT)), np.exp(rng.uniform(*LOG_VT))
    a = A_MIN + (m - m * A_MIN) * rng.dirichlet(np.ones(m))
    return pl.PlParams(i_t=float(i_t), v_t=float(v_t), w=rng.uniform(-W_BOUND, W_BOUND, n + 1),
                       v_b=float(rng.uniform(-W_BOUND, W_BOUND)), a=a)
