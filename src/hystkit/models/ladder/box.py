"""The ladder fit's box and the family's documented domain drawn from it (:func:`random_params`);
light (no optimiser loaded), so the family object reads it at import.
"""

from __future__ import annotations

import numpy as np

from .._docs import docfiller
from . import model as ladder

fill_doc = docfiller()

__all__ = ["BAND", "LOG_G_MIN", "W_BOUND", "random_params"]


BAND = (0.0, 1.5)  # normalised data (eq. 5.10): a band beyond the range never conducts
LOG_G_MIN = np.log(1e-3)
W_BOUND = 100.0  # as the mPL's |w| <= 100 (sec. 5.3.3)


@fill_doc
def random_params(structure: ladder.LadderStructure,
                  rng: np.random.Generator) -> ladder.LadderParams:
    """Parameters drawn from the fit's bounds (the family's documented domain): bands ``E_k``
    uniform in ``[0, 1.5]``, ``G_k`` log-uniform in ``[1e-3, slope_cap / (2 dt)]``, ``w_0..w_N``
    uniform in ``[-100, 100]``, ``V_b`` too (the fit leaves it free).

    Parameters
    ----------
    structure : ladder.LadderStructure
        The model's structure.
    %(rng)s

    Returns
    -------
    ladder.LadderParams
        The drawn parameters.
    """
    n = structure.n_cells
    band = rng.uniform(*BAND, n)
    g = np.exp(rng.uniform(LOG_G_MIN, np.log(ladder.conductance_limit(structure)), n))
    return ladder.LadderParams(band=band, conductance=g, w=rng.uniform(-W_BOUND, W_BOUND, n + 1),
                               v_b=float(rng.uniform(-W_BOUND, W_BOUND)))
