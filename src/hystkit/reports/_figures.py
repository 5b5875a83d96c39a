"""Figures of a compensation result. Each returns its Figure; nothing is shown or styled globally."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from ..io import Recording

__all__ = ["plot_loops", "plot_time_series"]


def plot_loops(results: Mapping[str, tuple[Recording, np.ndarray, np.ndarray]]) -> Figure:
    """Hysteresis loops before and after compensation, one column per recording.

    Parameters
    ----------
    results : mapping name -> (recording, estimate [mm], linear estimate [mm])
    """
    fig = Figure(figsize=(3.2 * len(results), 6.0), layout="constrained")
    axes = fig.subplots(2, len(results), squeeze=False)
    for col, (name, (rec, estimate, linear)) in enumerate(results.items()):
        top, bottom = axes[0, col], axes[1, col]
        top.plot(rec.position, rec.sensor, lw=0.6, color="tab:purple")
        top.set(title=f"{name}: sensor", xlabel="position [mm]", ylabel="ΔR1/R1 − ΔR2/R2")
        p = rec.position - rec.position.mean()
        lo, hi = p.min(), p.max()
        bottom.plot(p, linear - linear.mean(), lw=0.6, color="tab:blue", alpha=0.5,
                    label="straight line")
        bottom.plot(p, estimate - estimate.mean(), lw=0.6, color="tab:orange", label="mPL")
        bottom.plot([lo, hi], [lo, hi], color="k", lw=0.8, ls="--")
        bottom.set(title=f"{name}: compensated", xlabel="position [mm]",
                   ylabel="estimate [mm]")
    axes[1, 0].legend(loc="upper left", fontsize="small")
    return fig


def plot_time_series(results: Mapping[str, tuple[Recording, np.ndarray, np.ndarray]],
                     seconds: float = 20.0) -> Figure:
    """Measured and estimated position over the first ``seconds`` of each recording."""
    fig = Figure(figsize=(10.0, 2.2 * len(results)), layout="constrained")
    axes = fig.subplots(len(results), 1, squeeze=False)[:, 0]
    for ax, (name, (rec, estimate, linear)) in zip(axes, results.items()):
        keep = rec.time <= rec.time[0] + seconds
        ax.plot(rec.time[keep], rec.position[keep], color="k", lw=1.0, label="position")
        ax.plot(rec.time[keep], linear[keep], color="tab:blue", lw=0.8, alpha=0.6,
                label="straight line")
        ax.plot(rec.time[keep], estimate[keep], color="tab:orange", lw=0.8, label="mPL")
        ax.set(title=name, ylabel="mm")
    axes[-1].set_xlabel("time [s]")
    axes[0].legend(loc="upper right", fontsize="small", ncols=3)
    return fig
