"""One sample of a cell model read out through an output resistor ``g`` (eq. 5.17), forward,
inverse and linearised: the same in the mpl-poly and mpl-g families, which differ only in their
cell resistors (cubic or sinh) and in how they find ``g``'s branch. Each function takes those as
arguments; ``_cubic_output_code.py`` is the same step in C and MATLAB.

The records read are ``params.w`` (``w_0 .. w_N``), ``params.v_b``, ``structure.dt``; the
output voltage is ``z = w_0 e + sum w_k x_k - V_b`` and each cell moves by Euler,
``x_k+ = x_k + f_k(e - x_k) dt``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["output_invert_step", "output_linearisation", "output_step"]

# cells(structure, params, v) -> f_k(v_k), shape (N,): the limited cell resistors' currents
CellCurrents = Callable[[Any, Any, np.ndarray], np.ndarray]


def output_step(structure: Any, params: Any, x: np.ndarray, u: float,
                output: Callable[[Any, float], float],
                cells: CellCurrents) -> tuple[float, np.ndarray]:
    """``y = g(z)`` from the present state and input ``u = e``, then the cells' Euler step.

    Parameters
    ----------
    structure, params : Record
        The family's records.
    x : numpy.ndarray, shape (N,)
        Cell voltages before the sample.
    u : float
        Input of the sample.
    output : callable
        ``output(params, z) -> g(z)``.
    cells : callable
        ``cells(structure, params, v)``: the cell resistors' currents at voltages ``v``.

    Returns
    -------
    y : float
        Output of the sample.
    x_next : numpy.ndarray
        State after the sample.
    """
    x = np.asarray(x, dtype=float)
    y = output(params, params.w[0] * u + params.w[1:] @ x - params.v_b)
    return float(y), x + cells(structure, params, u - x) * structure.dt


def output_invert_step(structure: Any, params: Any, x: np.ndarray, z: float,
                       cells: CellCurrents) -> tuple[float, np.ndarray]:
    """The input ``e`` that gives output voltage ``z`` from the present state (as eq. 5.13),
    then the cells' Euler step driven by it (fig. 5.12).

    Parameters
    ----------
    structure, params, x, cells
        As :func:`output_step`.
    z : float
        Output voltage to reach (``g(z)`` the output wanted, on the family's branch).

    Returns
    -------
    u : float
        Input that gives `z` from the present state.
    x_next : numpy.ndarray
        State after the sample.
    """
    x = np.asarray(x, dtype=float)
    e = (z - params.w[1:] @ x + params.v_b) / params.w[0]
    return float(e), x + cells(structure, params, e - x) * structure.dt


def output_linearisation(structure: Any, params: Any, x: np.ndarray, u: float, inverse: bool,
                         solve: Callable[[float], tuple[float, bool]],
                         output_slope: Callable[[Any, float], float],
                         cell_slopes: Callable[[np.ndarray], np.ndarray]
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Paper 9.2 eq. 2-7: ``(A, B, C, D)`` of one step at state ``x`` and input (inverse:
    output) ``u``. Forward: ``dx+ = (1 - f' dt) dx + f' dt du``, ``dy = g'(z) (w_0 du + w . dx)``.
    Inverse: ``dz = dy / g'(z)``, ``de = (dz - w . dx) / w_0``, the cells driven by ``e``.

    Parameters
    ----------
    structure, params : Record
        The family's records.
    x : numpy.ndarray, shape (N,)
        State to linearise at.
    u : float
        Input (with `inverse`: output) to linearise at.
    inverse : bool
        Linearise the inverse.
    solve : callable
        ``solve(y) -> (z, ok)``: the ``z`` on the branch with ``g(z) = y``; ``ok`` false when
        ``y`` is outside the branch's range.
    output_slope : callable
        ``output_slope(params, z) -> g'(z)``.
    cell_slopes : callable
        ``cell_slopes(v) -> f'_k(v_k)``, shape (N,): the limited cell resistors' slopes.

    Returns
    -------
    A : numpy.ndarray, shape (N, N)
    B, C : numpy.ndarray, shape (N,)
    D : float

    Raises
    ------
    ValueError
        With `inverse`, if `u` is outside the range of ``g``'s branch.
    """
    x = np.asarray(x, dtype=float)
    w0, w = params.w[0], params.w[1:]
    if inverse:
        z, ok = solve(u)
        if not ok:
            raise ValueError(f"output {u:.4g} is outside the range of g's branch: the "
                             f"inverse is not defined there")
        drive = (z - w @ x + params.v_b) / w0
    else:
        drive = u
        z = w0 * u + w @ x - params.v_b
    dg = float(output_slope(params, z))
    g = cell_slopes(drive - x) * structure.dt
    if inverse:
        return (np.diag(1.0 - g) - np.outer(g, w) / w0, g / (w0 * dg), -w / w0,
                float(1.0 / (w0 * dg)))
    return np.diag(1.0 - g), g, dg * w, float(dg * w0)
