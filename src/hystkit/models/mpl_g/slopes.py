"""The monotone output resistor of the mpl-g fit: ``g'`` written by its Bernstein coefficients on
``|z| <= MONOTONE_RANGE``, all of one sign, so that a fitted ``g`` is strictly monotone there
(see :mod:`.fit`); the map from those slopes to ``g``'s coefficients and back.
"""

from __future__ import annotations

import numpy as np

from . import model as mpl_g

MONOTONE_RANGE = 2.0
"""Half-width of the interval ``|z| <= R`` (normalised units, gauge ``w_0 = 1``, ``V_b = 0``) on
which a fitted ``g`` is strictly monotone."""


def slope_matrix(r: float) -> np.ndarray:
    """``M`` with ``(g_1, g_2, g_3) = M b`` for ``g' = b_0 (1-t)^2 + 2 b_1 t (1-t) + b_2 t^2``,
    ``t = (z + r) / (2 r)`` (expanded in ``z``, then integrated)."""
    s = 1.0 / (2.0 * r)
    return np.array([[0.25, 0.5, 0.25],
                     [-0.5 * s, 0.0, 0.5 * s],
                     [s * s / 3.0, -2.0 * s * s / 3.0, s * s / 3.0]])


def output_from_slopes(g0: float, b: np.ndarray, r: float = MONOTONE_RANGE) -> np.ndarray:
    """``g_0..g_3`` of the cubic with ``g(0) = g0`` whose slope has Bernstein coefficients
    ``b`` on ``|z| <= r``; ``g`` is strictly monotone there when all ``b`` share a sign.

    Parameters
    ----------
    g0 : float
        ``g(0)``.
    b : array, shape (3,)
        Bernstein coefficients of ``g'`` on ``[-r, r]``.
    r : float, default MONOTONE_RANGE
        Half-width of the interval.

    Returns
    -------
    numpy.ndarray, shape (4,)
        ``g_0..g_3``.
    """
    return np.r_[g0, slope_matrix(r) @ np.asarray(b, dtype=float)]


def bernstein_slopes(g: np.ndarray, r: float = MONOTONE_RANGE) -> np.ndarray:
    """Inverse of :func:`output_from_slopes` (without ``g_0``): ``b_0 = g'(-r)``,
    ``b_2 = g'(r)``, ``b_1 = 2 g'(0) - (b_0 + b_2) / 2``.

    Parameters
    ----------
    g : array, shape (4,)
        ``g_0..g_3``.
    r : float, default MONOTONE_RANGE
        Half-width of the interval.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``b_0, b_1, b_2``.
    """
    g = np.asarray(g, dtype=float)
    lo, mid, hi = (mpl_g.output_slope(mpl_g.MplGParams(i_s=[1.0], v_t=[1.0], g=g, w=[1.0, 0.0]),
                                      z) for z in (-r, 0.0, r))
    return np.array([lo, 2.0 * mid - 0.5 * (lo + hi), hi])
