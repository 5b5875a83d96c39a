"""The Chua-Stromsmoe fit's box in optimiser coordinates (:func:`fit_bounds`) and the family's
documented domain drawn from it (:func:`random_params`); light (no optimiser loaded), so the
family object reads it at import.
"""

from __future__ import annotations

import numpy as np

from .._docs import docfiller
from . import model as chua

fill_doc = docfiller()

__all__ = ["DELTA", "LOG_SCALE", "LOG_SLOPE", "LOG_VG", "fit_bounds", "random_params"]


# Bounds per element in optimiser coordinates, for data normalised to max |.| = 1 (eq. 5.10):
# slopes and scales over four decades around 1, bands up to the whole half-range.
LOG_SLOPE = (np.log(1e-2), np.log(1e2))
LOG_SCALE = (np.log(1e-2), np.log(1e2))
LOG_VG = (np.log(1e-3), np.log(1e3))
DELTA = (0.0, 1.0)


def fit_bounds(structure: chua.ChuaStructure) -> tuple[np.ndarray, np.ndarray]:
    """The fit's ``(lower, upper)`` bounds in optimiser coordinates, element by element."""
    # Beyond the Euler cap g is a straight line of the capped slope, so a larger G changes
    # nothing: 100 / dt is above the cap for any restoring slope >= 1e-2.
    log_g = (np.log(1e-3), np.log(min(100.0 / structure.dt, chua.DOMAIN["g"][1])))
    per = [LOG_SLOPE, LOG_SLOPE, LOG_SCALE, log_g, LOG_VG, DELTA]
    lower, upper = (np.tile([b[i] for b in per], structure.n_elements) for i in (0, 1))
    return lower, upper


@fill_doc
def random_params(structure: chua.ChuaStructure, rng: np.random.Generator) -> chua.ChuaParams:
    """Parameters drawn from the fit's bounds (the family's documented domain), per element:
    ``k_0``, ``k_inf``, ``y_s`` log-uniform in ``[1e-2, 1e2]``, ``G`` log-uniform in
    ``[1e-3, 100 / dt]``, ``V_g`` log-uniform in ``[1e-3, 1e3]``, ``delta`` uniform in ``[0, 1]``.

    Parameters
    ----------
    structure : chua.ChuaStructure
        The model's structure.
    %(rng)s

    Returns
    -------
    chua.ChuaParams
        The drawn parameters.
    """
    lower, upper = fit_bounds(structure)
    return chua.ChuaParams.from_vector(rng.uniform(lower, upper), structure.n_elements)
