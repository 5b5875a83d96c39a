"""The ch. 7 compensators of paper 9.2's table II sensors, derived by the document's protocol.

The document prints no weights for the sinh-plus-``g`` compensator ``S_m^comp`` of sec. 7.2
(fig. 7.3b gives only its R^2 = 0.995), and table II's columns cannot be presets of this family:
their cell resistors are cubics with a constant and a quadratic term (``f_0 = -4.719``,
``f_2^2 = 1.548`` in the noise column), which no odd sinh cell reproduces. What sec. 7.2 does
with table II is what this module does: run a column as the "real" sensor ``S_r`` (its inverse,
position -> sensor, as ``hystkit.control.table_ii_sensor``) on the training excitation
``r(t) = 3 mm sin(pi t)`` (eq. 7.3, 200 s at the paper's 40 Hz), and fit the compensator
directly, sensor -> position, on that response (fig. 7.3), N = 1.
"""

from __future__ import annotations

import functools

import numpy as np

from ..mpl_poly import FAMILY as MPL_POLY
from .fit import fit_mpl_g
from .model import MplGParams, MplGStructure, simulate

__all__ = ["TRAINING_DT", "TRAINING_SECONDS", "ch7_compensator", "table_ii_response"]

TRAINING_DT = 0.025
"""Sample time of paper 9.2's data [s] (40 Hz), the rate table II was fitted at."""
TRAINING_SECONDS = 200.0
"""Length of the training run [s], as the paper's sine recording."""


def table_ii_response(column: str) -> tuple[np.ndarray, np.ndarray]:
    """Table II ``column`` run as a sensor on the normalised training sine.

    Parameters
    ----------
    column : {"sine", "chirp", "decay", "noise"}
        Column of paper 9.2's table II (one of its four fitted compensators).

    Returns
    -------
    position : array, shape (8000,)
        ``sin(pi t)``: eq. 7.3 normalised by its 3 mm amplitude.
    sensor : array, shape (8000,)
        The column's inverse (position -> sensor) from rest, normalised sensor units.

    Raises
    ------
    ValueError
        If table II has no such column.
    """
    presets = MPL_POLY.presets()
    key = f"table-ii-{column}"
    if key not in presets:
        names = sorted(k.removeprefix("table-ii-") for k in presets)
        raise ValueError(f"table II has columns {names}, got {column!r}")
    structure, params, _ = presets[key]
    t = np.arange(round(TRAINING_SECONDS / TRAINING_DT)) * TRAINING_DT
    position = np.sin(np.pi * t)
    sensor, _ = MPL_POLY.invert(structure, params, position)
    return position, sensor


@functools.cache
def ch7_compensator(column: str = "noise") -> tuple[MplGStructure, MplGParams, dict]:
    """The sec. 7.2 compensator (N = 1, direct: sensor -> position) of table II ``column``.

    Both signals are centred and normalised to max |.| = 1 (eq. 5.10) before the fit; ``info``
    holds the centres and scales (to use the model on raw signals) and the fit's R^2 (the
    document: 0.995 for its compensator of the noise column, fig. 7.3b). About 1-3 s per
    column, cached.

    Parameters
    ----------
    column : {"sine", "chirp", "decay", "noise"}, default "noise"
        Column of paper 9.2's table II (as :func:`table_ii_response`).

    Returns
    -------
    structure : MplGStructure
        ``N = 1`` at ``TRAINING_DT``.
    params : MplGParams
        The fitted parameters (normalised units).
    info : dict
        Source, direction, ``fit_dt``, ``r2``, ``converged`` and the centres and scales of
        sensor and position.

    Raises
    ------
    ValueError
        If table II has no such column.
    """
    position, sensor = table_ii_response(column)
    s_mean, p_mean = float(sensor.mean()), float(position.mean())
    s_scale = float(np.max(np.abs(sensor - s_mean)))
    p_scale = float(np.max(np.abs(position - p_mean)))
    u, y = (sensor - s_mean) / s_scale, (position - p_mean) / p_scale
    structure = MplGStructure(n_cells=1, dt=TRAINING_DT)
    result = fit_mpl_g(u, y, structure)
    y_fit, _ = simulate(structure, result.params, u)
    r2 = 1.0 - float(np.sum((y_fit - y) ** 2) / np.sum((y - y.mean()) ** 2))
    info = {"source": f"fitted by hystkit on paper 9.2 table II, {column} column, run as S_r on "
                      f"3 mm sin(pi t), 200 s at 40 Hz (sec. 7.2 protocol)",
            "direction": "sensor -> position", "fit_dt": TRAINING_DT, "r2": r2,
            "converged": bool(result.converged), "sensor_center": s_mean,
            "sensor_scale": s_scale, "position_center": p_mean, "position_scale": p_scale}
    return structure, result.params, info
