"""The loop analysis's verdicts in plain words, apart from the analysis itself (which loads
python-control and scipy): the CLI and the report load these when they start."""

from __future__ import annotations

import math

__all__ = ["slow_cell_words"]


def slow_cell_words(max_pole_radius: float, growth_time_s: float, block: str,
                    time_constant_s: float, run_s: float) -> str:
    """A growing mode no faster than a slow cell, in one plain line (``hystkit control`` and
    ``report``): marginal, from that cell, with its e-folding time and its growth over a run.

    The mode is slower than every cell of the loop's models: what grows is one of the
    integrators (plant, PID) at ``z = 1``, moved beyond the circle by less than the slow cell
    sits inside it. A cell that slow is often at the fit's bound, where the data cannot tell
    it from an integrator (e.g. mPL's 1e4 s floor, ``hystkit.models.mpl.fit``), and a
    slightly faster one moves the pole inside: the sign of ``|pole| - 1`` at that level says
    what the fitted numbers give, not what the sensor does.

    Parameters
    ----------
    max_pole_radius : float
        The growing pole's radius.
    growth_time_s : float
        Its e-folding time [s].
    block : str
        The block with the slow cell (``sensor``, ``compensator``).
    time_constant_s : float
        The cell's time constant [s].
    run_s : float
        The run length [s] over which the growth is quoted.

    Returns
    -------
    str
        ``marginal, from a slow cell: ...`` (no leading ``closed loop``).
    """
    factor = math.exp(run_s / growth_time_s)
    return (f"marginal, from a slow cell: one mode (|pole| 1 + {max_pole_radius - 1:.2g}), "
            f"slower than the slowest cell of the {block} (time constant {time_constant_s:.3g} s), "
            f"drifts e-fold in {_duration(growth_time_s)}, a factor {factor:.4f} over a "
            f"{run_s / 60:g}-minute run: bounded over runs much shorter than that, not "
            f"asymptotically stable")


def _duration(seconds: float) -> str:
    """``8.1e+05 s (9.38 days)``: seconds, and in hours or days when that long."""
    for unit, size in (("days", 86400.0), ("hours", 3600.0)):
        if seconds >= 2 * size:
            return f"{seconds:.3g} s ({seconds / size:.3g} {unit})"
    return f"{seconds:.3g} s"
