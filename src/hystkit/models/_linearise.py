"""Discrete linearisation of one model step by central differences, the default of
:meth:`hystkit.models.Family.linearise`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def numerical_linearisation(step: Callable[[np.ndarray, float], tuple[float, np.ndarray]],
                            x: np.ndarray, u: float,
                            rel_step: float = 1e-6) -> tuple[np.ndarray, np.ndarray,
                                                             np.ndarray, float]:
    """``(A, B, C, D)`` of ``(y, x+) = step(x, u)`` by central differences.

    The step is ``rel_step`` times ``max(1, |value|)`` per coordinate; a piecewise model
    linearised exactly on a kink gets the mean of its two slopes.

    Parameters
    ----------
    step : callable
        ``step(x, u) -> (y, x_next)`` with the parameters bound.
    x : numpy.ndarray, shape (n,)
        State to linearise at.
    u : float
        Input to linearise at.
    rel_step : float, default 1e-6
        Relative finite-difference step.

    Returns
    -------
    A : numpy.ndarray, shape (n, n)
        d x_next / d x.
    B : numpy.ndarray, shape (n,)
        d x_next / d u.
    C : numpy.ndarray, shape (n,)
        d y / d x.
    D : float
        d y / d u.
    """
    x = np.array(x, dtype=float)
    n = x.size
    a = np.empty((n, n))
    c = np.empty(n)
    for k in range(n):
        h = rel_step * max(1.0, abs(x[k]))
        xp, xm = x.copy(), x.copy()
        xp[k] += h
        xm[k] -= h
        (yp, xnp), (ym, xnm) = step(xp, u), step(xm, u)
        a[:, k] = (np.asarray(xnp) - np.asarray(xnm)) / (2 * h)
        c[k] = (yp - ym) / (2 * h)
    h = rel_step * max(1.0, abs(u))
    (yp, xnp), (ym, xnm) = step(x, u + h), step(x, u - h)
    b = (np.asarray(xnp) - np.asarray(xnm)) / (2 * h)
    return a, b, c, float((yp - ym) / (2 * h))
