"""Figures of the per-cycle and settling analysis; each returns its Figure, nothing is shown.

:func:`plot_cycles` draws the document's figs. 4.16-4.17: the chosen cycles' loops of each
signal against the position (one panel per signal, cycles coloured by time), and below them
the offset of every cycle against time with its fitted drift line. :func:`plot_settling`
draws fig. 3.5: each resistance log with its fitted law against hours since printing
(logarithmic, as the document recommends), and the rest time.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ._per_cycle import CycleTable
from ._rest_time import RestTime
from ._settling import SettlingFit, settling_curve

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_cycles", "plot_settling"]

_MAX_LABELLED = 8  # cycles named in the legend; beyond, only the first and the last


def plot_cycles(x: np.ndarray, signals: Mapping[str, np.ndarray], table: CycleTable,
                cycles: Sequence[int], *, scale: float = 100.0,
                unit: str = "%", x_label: str = "position [mm]") -> Figure:
    """Loops of the chosen cycles per signal, and every cycle's offset over time.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Input (position [mm]).
    signals : mapping of str to ndarray, shape (n,)
        The signals of `table`, drawn times `scale` in `unit` (dR/R in % by default).
    table : CycleTable
    cycles : sequence of int
        Cycle numbers (1-based, complete cycles) to draw, coloured by time (viridis).
    scale : float, default 100.0
        Factor the signals are drawn with.
    unit : str, default "%"
        Unit of the scaled signals, for the axis labels.
    x_label : str, default "position [mm]"
        Label of the loops' horizontal axis.

    Returns
    -------
    matplotlib.figure.Figure
        The loops, one panel per signal, and every cycle's offset over time.
    """
    from matplotlib import colormaps  # here: the tables need no matplotlib
    from matplotlib.figure import Figure

    names = list(signals)
    fig = Figure(figsize=(4.2 * len(names), 7.0), layout="constrained")
    grid = fig.add_gridspec(2, len(names), height_ratios=(3, 2))
    colors = colormaps["viridis"](np.linspace(0.0, 0.9, len(cycles)))
    for j, name in enumerate(names):
        ax = fig.add_subplot(grid[0, j])
        for i, (k, color) in enumerate(zip(cycles, colors, strict=True)):
            a, b = table.start[k - 1], table.stop[k - 1] + 1  # closed loop
            # many cycles (fig. 4.13): the colour gives the time, the legend the two ends
            labelled = len(cycles) <= _MAX_LABELLED or i in (0, len(cycles) - 1)
            ax.plot(x[a:b], scale * signals[name][a:b], color=color, lw=1.0,
                    label=f"cycle {k} (t = {table.t_start[k - 1]:.4g} s)" if labelled
                    else None)
        ax.set_title(name)
        ax.set_xlabel(x_label)
        ax.set_ylabel(f"{name} [{unit}]")
        ax.grid(alpha=0.3)
        if j == 0:
            ax.legend(fontsize="small")
    ax = fig.add_subplot(grid[1, :])
    for name in names:
        line, = ax.plot(table.t_mid, scale * table.offset[name], "o", ms=3, label=name)
        drift = table.drift.get(name)
        if drift is not None:
            t = table.t_mid
            fitted = table.offset[name].mean() + drift.per_hour / 3600 * (t - t.mean())
            ax.plot(t, scale * fitted, color=line.get_color(), lw=1,
                    label=f"{name}: {scale * drift.per_hour:.3g} {unit}/h")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"cycle offset [{unit}]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", ncol=2)
    return fig


def plot_settling(logs: Mapping[str, tuple[np.ndarray, np.ndarray, SettlingFit | None,
                                            RestTime | None]]) -> Figure:
    """Each log (hours, resistance [Ohm]) with its fit and rest time, log time axis.

    Parameters
    ----------
    logs : mapping of str to (t_h, r, fit, rest)
        `fit` and `rest` None for a column that could not be fitted (drawn without a curve).

    Returns
    -------
    matplotlib.figure.Figure
        One panel per log.
    """
    from matplotlib.figure import Figure  # here: as in plot_cycles

    fig = Figure(figsize=(7.5, 2.6 * len(logs)), layout="constrained")
    axes = fig.subplots(len(logs), 1, squeeze=False)[:, 0]
    for ax, (name, (t_h, r, fit, rest)) in zip(axes, logs.items(), strict=True):
        shown = t_h > 0  # a log axis has no t = 0
        ax.plot(t_h[shown], r[shown] / 1e3, ".", ms=2, color="0.6", label=f"{name} (log)")
        if fit is not None:
            ax.plot(t_h[shown], settling_curve(fit.params, t_h[shown]) / 1e3, color="tab:red",
                    lw=1.2, label=f"fit ({fit.model})")
        if rest is not None and rest.hours > 0:
            extra = ", extrapolated" if rest.extrapolated else ""
            ax.axvline(rest.hours, color="k", ls="--", lw=1,
                       label=f"rest {rest.hours / 24:.2f} d (|dR/dt| / R_final < "
                             f"{rest.threshold_pct_per_hour:g} %/h{extra})")
        ax.set_xscale("log")
        ax.set_ylabel("R [kOhm]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize="small")
    axes[-1].set_xlabel("time since printing [h]")
    return fig
