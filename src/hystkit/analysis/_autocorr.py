"""Lag-1 autocorrelation of residuals and the AR(1) inflation of a standard error.

Slowly varying errors (temperature drift of a settling log, the creep transient of cycle
offsets) make neighbouring residuals alike; a standard error computed as if they were
independent is then too small. Both the settling fit and the cycle drift rate inflate theirs by
the same factor, from the residuals' lag-1 autocorrelation.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

__all__ = ["ar1_inflation", "lag1"]


def ar1_inflation(rho: float) -> float:
    """Factor on an i.i.d. standard error for residuals with lag-1 autocorrelation `rho`.

    For AR(1) errors the effective sample size of a mean or a slope is about
    ``n (1 - rho) / (1 + rho)``, so standard errors grow by ``sqrt((1 + rho) / (1 - rho))``;
    a negative `rho` is not credited (factor 1).

    Parameters
    ----------
    rho : float
        Lag-1 autocorrelation, in (-1, 1).

    Returns
    -------
    float
        The factor, >= 1 (infinite for ``rho >= 1``).
    """
    if rho <= 0:
        return 1.0
    return math.sqrt((1 + rho) / (1 - rho)) if rho < 1 else math.inf


def lag1(e: npt.ArrayLike) -> float:
    """Lag-1 autocorrelation of a series about its mean (0 for a constant series).

    Parameters
    ----------
    e : array_like, shape (n,)
        Residuals or any series.

    Returns
    -------
    float
        ``sum(e_i e_(i+1)) / sum(e_i^2)`` of the centred series.
    """
    e = np.asarray(e, dtype=float)
    e = e - e.mean()
    den = float(np.sum(e * e))
    return float(np.sum(e[1:] * e[:-1]) / den) if den > 0 else 0.0
