"""Slope sectors of the loop's hysteretic blocks, measured: what the circle criterion
(``_stability.py``) assumes of them.

The block is driven over its training range (the trained 0.5 Hz, 3 mm sine of sec. 7.2, at the
loop's ``Ts``) and the chord slopes of consecutive samples are taken where the input moves. A
dynamic model (the mPL is an ODE) can change its output while its input stands still; those
samples are left out and how far they fall outside the sector is reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._experiments import sine_reference
from ._loop import ControlLoop

__all__ = ["RELATIVE_STEP", "Sector", "chord_sector", "hull", "interval", "measure_sector"]

RELATIVE_STEP = 1e-2
"""Chord slopes are taken where ``|du| > RELATIVE_STEP * max |du|`` (the input moves)."""


@dataclass(frozen=True)
class Sector:
    """Measured slope sector ``[k_min, k_max]`` of a block's increments.

    Parameters
    ----------
    k_min, k_max : float
        Smallest and largest chord slope ``dv / du`` [output units per input unit].
    n_used, n_samples : int
        Increments the slopes come from, of all.
    unexplained_step : float
        How far the left-out increments (input nearly still) fall outside the sector: the
        largest distance of ``dv`` from ``[k_min du, k_max du]``, relative to the largest
        ``|dv|`` of all. 0 (to rounding) for a memoryless block.
    units : str, default ""
        Units of the slopes, e.g. ``"m / m"``.
    """

    k_min: float
    k_max: float
    n_used: int
    n_samples: int
    unexplained_step: float
    units: str = ""

    def to_dict(self) -> dict:
        """The fields as a JSON-safe dict."""
        return dict(vars(self))


def chord_sector(u: np.ndarray, v: np.ndarray, *, relative_step: float = RELATIVE_STEP,
                 units: str = "") -> Sector:
    """Sector of the chord slopes ``(v[n+1] - v[n]) / (u[n+1] - u[n])`` of a block's run.

    Parameters
    ----------
    u, v : arrays, shape (n,)
        Input and output of one run.
    relative_step : float
        Increments with ``|du| <= relative_step * max |du|`` are left out (see :class:`Sector`).
    units : str, default ""
        Units of the slopes, stored in the result.

    Returns
    -------
    Sector
        Slopes of the used increments and how far the others fall outside.

    Raises
    ------
    ValueError
        If the input does not move (no increment to take a slope of).
    """
    du, dv = np.diff(np.asarray(u, dtype=float)), np.diff(np.asarray(v, dtype=float))
    if du.size == 0 or not np.any(du):
        raise ValueError("the input does not move: no slope to measure")
    used = np.abs(du) > relative_step * np.max(np.abs(du))
    k = dv[used] / du[used]
    k_min, k_max = float(k.min()), float(k.max())
    lo = np.minimum(k_min * du[~used], k_max * du[~used])
    hi = np.maximum(k_min * du[~used], k_max * du[~used])
    outside = np.maximum(lo - dv[~used], dv[~used] - hi)
    top = np.max(np.abs(dv))
    unexplained = (float(max(np.max(outside, initial=0.0), 0.0) / top) if top > 0 else 0.0)
    return Sector(k_min, k_max, int(used.sum()), int(du.size), unexplained, units)


def _training_position(ts: float) -> np.ndarray:
    """The trained sine (eq. 7.3, 0.5 Hz, 3 mm), 3 periods at ``ts`` [m]."""
    return sine_reference(round(6.0 / ts), ts)


def measure_sector(loop: ControlLoop, y: np.ndarray | None = None) -> dict[str, Sector]:
    """Slope sectors of the loop's hysteretic blocks, driven by the position ``y`` [m].

    ``y`` defaults to the trained sine (eq. 7.3, 3 periods at ``loop.ts``). Returns the sectors
    of ``S_r`` (position -> sensor), of the compensator (sensor -> position, on ``S_r``'s
    output) when present, and of the channel the circle criterion uses: ``y -> y_hat``
    (compensator after ``S_r``) in scheme ``direct``, ``S_r`` itself in ``weighting``.

    Parameters
    ----------
    loop : ControlLoop
        The loop whose blocks are measured (run open loop, each from rest).
    y : numpy.ndarray, shape (n,), optional
        Plant position [m] driving ``S_r``; default the trained sine.

    Returns
    -------
    dict of str to Sector
        ``"sensor"``, ``"compensator"`` (with a compensator) and ``"channel"`` (scheme
        ``direct`` with a compensator, or ``weighting``).

    Raises
    ------
    ValueError
        If `y` does not move.
    """
    y = _training_position(loop.ts) if y is None else np.asarray(y, dtype=float)
    s, _ = loop.sensor.simulate(y, loop.ts)
    out = {"sensor": chord_sector(y, s, units="sensor units / m")}
    if loop.compensator is not None:
        y_hat, _ = loop.compensator.simulate(s, loop.ts)
        out["compensator"] = chord_sector(s, y_hat, units="m / sensor unit")
        if loop.scheme == "direct":
            out["channel"] = chord_sector(y, y_hat, units="m / m")
    if loop.scheme == "weighting":
        out["channel"] = out["sensor"]
    return out


def hull(parts: list[Sector], units: str) -> Sector:
    """The smallest sector holding every one of ``parts`` (their increments pooled)."""
    return Sector(min(p.k_min for p in parts), max(p.k_max for p in parts),
                  sum(p.n_used for p in parts), sum(p.n_samples for p in parts),
                  max(p.unexplained_step for p in parts), units)


def interval(s: Sector) -> str:
    return f"[{s.k_min:.4g}, {s.k_max:.4g}] {s.units}"
