"""Polynomial mPL (sec. 5.3.5, paper 9.2) as a loop block, and paper 9.2's table II as ``S_r``.

:class:`~hystkit.control.SensorBlock` dispatches here when its parameters are
:class:`~hystkit.models.mpl_poly.MplPolyParams`. Forward: ``out = g(w_0 u + sum w_k x_k - V_b)``,
cells driven by ``u``. Inverse (the block runs a fitted model backwards, as ``mpl_poly.invert``):
``z = g^-1(in)`` on the monotone branch of ``g`` through the rest point (safeguarded Newton),
``u_hat = (z - sum w_k x_k + V_b) / w_0`` with the present state, cells driven by ``u_hat``.
The cell resistors are the limited cubics of eq. 5.29 with their knees recomputed for the
loop's sample time (``f' = slope_cap / Ts``), the same decision as for the sinh mPL.

Packed body after the common header (see :data:`~hystkit.control._sensors.BLOCK_HEADER`)::

    limit, lo, hi, sign, centre, g0..g3, f (N x 4, row-major), knees (N x 2), w (N + 1)

``lo, hi, sign, centre`` describe the output branch (``mpl_poly.output_branch``), used only in
inverse mode.
"""

from __future__ import annotations

import numpy as np

from ..errors import FitDivergedError
from ..identification.family_mpl_poly import PAPER_9_2_TABLE_II, paper_9_2_params
from ..models import _mpl_poly_kernels as kernels
from ..models import mpl_poly

__all__ = ["TABLE_II_POSITION_SCALE", "TABLE_II_SENSORS", "linearise", "pack_body",
           "rest_state", "simulate", "step", "table_ii_block"]

TABLE_II_SENSORS = tuple(f"table-ii-{name}" for name in PAPER_9_2_TABLE_II)
"""``--sensor`` choices: paper 9.2's table II columns run as the forward sensor ``S_r``."""

TABLE_II_POSITION_SCALE = 3e-3
"""Assumed position normalisation of paper 9.2's data [m]: the 3 mm stroke of every experiment
(the paper normalises by max |.|, eq. 5.10, but prints no scales)."""


def _branch(structure: mpl_poly.MplPolyStructure, p: mpl_poly.MplPolyParams):
    lo, hi, sign = mpl_poly.output_branch(structure, p)
    centre = -p.w[1:] @ mpl_poly.rest_voltages(structure, p) - p.v_b
    return lo, hi, sign, float(centre)


def _solve(structure, p, y: float) -> tuple[float, bool]:
    lo, hi, sign, centre = _branch(structure, p)
    z, ok = kernels.solve_output(float(y), np.ascontiguousarray(p.g), lo, hi, sign, centre)
    return float(z), bool(ok)


def rest_state(structure: mpl_poly.MplPolyStructure, p: mpl_poly.MplPolyParams, inverse: bool,
               u_norm: float) -> np.ndarray:
    """Cells at rest (``u_k = e - v*_k``) for a constant normalised block input.

    Inverse: ``e_0 = (z_0 + sum w_k v*_k + V_b) / sum w`` with ``g(z_0) = input``, as
    ``mpl_poly.invert`` starts (``e_0 = 0`` if the input is outside ``g``'s branch).
    """
    v_rest = mpl_poly.rest_voltages(structure, p)
    e0 = u_norm
    if inverse:
        z0, ok = _solve(structure, p, u_norm)
        w_sum = float(np.sum(p.w))
        e0 = (z0 + p.w[1:] @ v_rest + p.v_b) / w_sum if ok and w_sum != 0 else 0.0
    return e0 - v_rest


def step(structure, p, inverse: bool, x: np.ndarray, u_norm: float) -> tuple[float, np.ndarray]:
    """One readable sample in normalised units (``mpl_poly.step`` / ``invert_step``)."""
    if not inverse:
        return mpl_poly.step(structure, p, x, u_norm)
    if not _solve(structure, p, u_norm)[1]:  # outside g's branch: no inverse (the kernel: NaN)
        return np.nan, np.full(np.size(x), np.nan)
    return mpl_poly.invert_step(structure, p, x, u_norm)


def simulate(structure, p, inverse: bool, u_norm: np.ndarray,
             x0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Open-loop run in normalised units (compiled)."""
    run = mpl_poly.invert if inverse else mpl_poly.simulate
    return run(structure, p, u_norm, x0)


def pack_body(structure: mpl_poly.MplPolyStructure, p: mpl_poly.MplPolyParams) -> np.ndarray:
    """The block's parameters after the header, for ``_kernel._poly_block``."""
    try:
        lo, hi, sign, centre = _branch(structure, p)
    except FitDivergedError:  # forward-only use of a model whose g has no branch at rest
        lo, hi, sign, centre = -np.inf, np.inf, 0.0, 0.0
    return np.concatenate([[float(structure.limit), lo, hi, sign, centre], p.g,
                           p.f.reshape(-1), mpl_poly.knee_points(structure, p).reshape(-1),
                           p.w])


def linearise(structure, p, inverse: bool, x: np.ndarray, u_norm: float):
    """Discrete ``(A, B, C, D)`` in normalised units (paper 9.2 eq. 2-7 for both directions).

    Forward: ``dx+ = (1 - f' dt) dx + f' dt du``, ``dy = g'(z) (w_0 du + w . dx)``.
    Inverse: ``dz = dy / g'(z)``, ``de = (dz - w . dx) / w_0``, cells driven by ``e``.
    """
    x = np.asarray(x, dtype=float)
    dt = structure.dt
    w0, w = p.w[0], p.w[1:]
    if inverse:
        z, _ = _solve(structure, p, u_norm)
        drive = (z - w @ x + p.v_b) / w0
    else:
        drive = u_norm
        z = w0 * u_norm + w @ x - p.v_b
    dg = float(mpl_poly.output_slope(p, z))
    slope = mpl_poly.resistor_slope(structure, p, drive - x)
    g = slope * dt
    if inverse:
        return (np.diag(1.0 - g) - np.outer(g, w) / w0, g / (w0 * dg), -w / w0,
                1.0 / (w0 * dg))
    return np.diag(1.0 - g), g, dg * w, dg * w0


def table_ii_block(column: str = "noise", *, sensor_scale: float = 1.0,
                   sensor_offset: float = 0.0, dt: float = 0.025):
    """Paper 9.2's table II column as the forward "real" sensor ``S_r``: position [m] -> sensor.

    The column is a *direct compensator* fitted sensor -> position on normalised 40 Hz data
    (N = 1). As a sensor it runs backwards: the block is the model's inverse
    (``inverse=True``), position normalised by :data:`TABLE_II_POSITION_SCALE` in, the model's
    normalised sensor out -- the signal whose compensator the column is. ``sensor_scale`` and
    ``sensor_offset`` only choose the sensor's physical units (default: the normalised sensor
    itself, which spans about +-1 on full-range motion, as the paper's normalised data did;
    docs/control.md gives the measured span).
    """
    from ._sensors import SensorBlock  # circular at import time

    if column not in PAPER_9_2_TABLE_II:
        raise ValueError(f"table II has columns {sorted(PAPER_9_2_TABLE_II)}, got {column!r}")
    params = paper_9_2_params(PAPER_9_2_TABLE_II[column])
    structure = mpl_poly.MplPolyStructure(1, dt)
    return SensorBlock(structure, params, True, 0.0, TABLE_II_POSITION_SCALE, sensor_offset,
                       sensor_scale, name="S_r",
                       info={"source": f"paper 9.2 table II, {column} column (as printed, "
                             f"f2^2, f3^3)", "kind": "mpl-poly",
                             "direction": "position -> sensor (inverse of a sensor -> position "
                             "fit)", "n_cells": 1, "fit_dt": dt,
                             "position_scale_m": TABLE_II_POSITION_SCALE,
                             "sensor_scale": sensor_scale})
