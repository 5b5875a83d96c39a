"""The polynomial mPL model's cubic resistors: the cell resistors ``f_k`` with the corrected
stability limit of eq. 5.29 (knees and straight continuations) and the output resistor ``g``,
with their slopes.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from .._docs import ENTRIES, docfiller
from .records import (
    MplPolyParams,
    MplPolyStructure,
)

# The Parameters section of the output resistor's functions of its voltage (g and g').
_ENTRIES = {"output_voltage": "Parameters\n----------\n" + ENTRIES["params"] + """
z : numpy.ndarray
    Voltage across the output resistor."""}
fill_doc = docfiller("MplPolyStructure", "MplPolyParams", entries=_ENTRIES)


@fill_doc
def knee_points(structure: MplPolyStructure, params: MplPolyParams) -> np.ndarray:
    """Knees ``x-, x+`` of each cell, shape (N, 2): the extreme solutions of ``f'(x) = s``.

    ``s = slope_cap / dt``. With ``c3 > 0`` ``f'`` is an upward parabola, so ``f' > s`` exactly
    outside the knees; when it never drops to ``s`` both knees sit at its vertex.

    %(records_parameters)s

    Returns
    -------
    numpy.ndarray, shape (N, 2)
        ``x-, x+`` per cell.
    """
    s = structure.slope_cap / structure.dt
    c1, c2, c3 = params.f[:, 1], params.f[:, 2], params.f[:, 3]
    vertex = -c2 / (3 * c3)
    half_width = np.sqrt(np.maximum(c2 * c2 - 3 * c3 * (c1 - s), 0.0)) / (3 * c3)
    return np.column_stack([vertex - half_width, vertex + half_width])


def _cubic(c: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return (c[..., 0] + x * (c[..., 1] + x * (c[..., 2] + x * c[..., 3])),
            c[..., 1] + x * (2 * c[..., 2] + 3 * c[..., 3] * x))


def _resistor(structure: MplPolyStructure, params: MplPolyParams,
              v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(v, dtype=float)
    f, df = _cubic(params.f, v)
    if not structure.limit:
        return f, df
    knees = knee_points(structure, params)
    s = structure.slope_cap / structure.dt
    x_b = np.where(v >= knees[:, 1], knees[:, 1], knees[:, 0])
    outside = (v >= knees[:, 1]) | (v <= knees[:, 0])
    return (np.where(outside, _cubic(params.f, x_b)[0] + s * (v - x_b), f),
            np.where(outside, s, df))


@fill_doc
def resistor_current(structure: MplPolyStructure, params: MplPolyParams,
                     v: np.ndarray) -> np.ndarray:
    """Cell currents ``f_k,lim(v)`` (eq. 5.16 with 5.29 when ``structure.limit``).

    %(cell_voltages)s
    """
    return _resistor(structure, params, v)[0]


@fill_doc
def resistor_slope(structure: MplPolyStructure, params: MplPolyParams,
                   v: np.ndarray) -> np.ndarray:
    """Slopes ``f'_k,lim(v)``, shape (..., N): the cells' rates in eq. 5.20 and 5.26.

    %(cell_voltages)s
    """
    return _resistor(structure, params, v)[1]


@fill_doc
def output_current(params: MplPolyParams, z: np.ndarray) -> np.ndarray:
    """Output resistor current ``g(z)`` (eq. 5.17).

    %(output_voltage)s

    Returns
    -------
    numpy.ndarray
        ``g(z)``, same shape as `z`.
    """
    return _cubic(params.g, np.asarray(z, dtype=float))[0]


@fill_doc
def output_slope(params: MplPolyParams, z: np.ndarray) -> np.ndarray:
    """Output resistor slope ``g'(z)`` (``g'_0`` of eq. 5.19).

    %(output_voltage)s

    Returns
    -------
    numpy.ndarray
        ``g'(z)``, same shape as `z`.
    """
    return _cubic(params.g, np.asarray(z, dtype=float))[1]


def output_root(params: MplPolyParams, y: float, lo: float, hi: float) -> float:
    """The ``z`` with ``g(z) = y`` on the branch ``[lo, hi]`` (``+-inf``: unbounded) by bracketed
    root finding, the readable reference of ``kernels.solve_output``; brentq's ValueError when
    ``y`` is outside the branch's range."""
    a = lo if np.isfinite(lo) else -1e15
    b = hi if np.isfinite(hi) else 1e15
    # from a +-1e15 bracket to a 1e-15 tolerance takes ~101 halvings: more than brentq's
    # default 100 iterations in the worst case (found by tests/models/test_invert_step_fuzz.py)
    return brentq(lambda z: output_current(params, z) - y, a, b, xtol=1e-15, rtol=1e-15,
                  maxiter=200)
