"""Figures of the loop experiments (fig. 7.5-7.7, 7.10, 7.12-7.17) and of the Bode analysis.

Every function returns a :class:`matplotlib.figure.Figure` built without pyplot: no window, no
global state, safe under any backend (save it with ``fig.savefig``).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ._experiments import ExperimentResult
from ._loop_margins import LoopMargins
from ._simulate import LoopResponse

__all__ = ["plot_bode", "plot_cases", "plot_response"]

MM = 1e3  # plots show millimetres


def _mark_stop(ax, resp: LoopResponse) -> None:
    if not resp.bounded:
        ax.axvline(resp.stop_time, color="crimson", lw=1, ls="--")
        ax.text(resp.stop_time, 0.5, " unbounded", color="crimson", ha="left", va="center",
                transform=ax.get_xaxis_transform(), fontsize=8)


def plot_response(resp: LoopResponse, title: str = "") -> Figure:
    """Four panels as fig. 7.5 / 7.10: positions; sensor; tracking error; plant error.

    Parameters
    ----------
    resp : LoopResponse
        The run to show; a cut run is marked where it stopped.
    title : str, default ""
        Figure title (none when empty).

    Returns
    -------
    matplotlib.figure.Figure
        The figure, positions and errors in mm.
    """
    fig = Figure(figsize=(8.5, 8.0), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True)
    t = resp.t
    ax = axes[0]
    ax.plot(t, resp.r * MM, color="k", lw=1.0, label="reference r")
    ax.plot(t, resp.y * MM, color="C0", lw=1.2, label="plant y")
    if resp.y_hat is not None:
        ax.plot(t, resp.y_hat * MM, color="C1", lw=0.9, ls="--", label="estimate (compensator)")
    if resp.scheme == "weighting":
        ax.plot(t, resp.y_hat_plant * MM, color="C2", lw=0.9, ls=":",
                label="estimate (plant model, fig. 7.11)")
    ax.set_ylabel("position [mm]")
    ax.legend(fontsize=7, loc="upper right", ncol=2)
    ax = axes[1]
    ax.plot(t, resp.s, color="C3", lw=1.0, label="sensor s = S_r(y)")
    if resp.s_hat is not None and resp.scheme == "weighting":
        ax.plot(t, resp.s_hat, color="k", lw=0.9, ls="--", label="weighted reference S_m(r)")
    ax.set_ylabel("sensor [dR/R]")
    ax.legend(fontsize=7, loc="upper right")
    ax = axes[2]
    ax.plot(t, resp.e * MM, color="C4", lw=1.0)
    ax.set_ylabel("tracking error\n[mm]" if resp.scheme == "direct"
                  else "tracking error\n[mm equiv.]")
    ax = axes[3]
    ax.plot(t, resp.plant_error * MM, color="C0", lw=1.0)
    ax.set_ylabel("plant error\nr - y [mm]")
    ax.set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        _mark_stop(ax, resp)
    m = resp.metrics()
    if "e_p_max" in m:
        axes[3].set_title(f"e_p,max = {m['e_p_max']:.3g} m, e_p,mean = {m['e_p_mean']:.3g} m, "
                          f"e_p,rms = {m['e_p_rms']:.3g} m", fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def plot_cases(result: ExperimentResult) -> Figure:
    """One row per case: reference and plant position, and plant error.

    As fig. 7.6, 7.7, 7.12, 7.13, 7.16 and 7.17.

    Parameters
    ----------
    result : ExperimentResult
        The experiment to show.

    Returns
    -------
    matplotlib.figure.Figure
        The figure, positions and errors in mm.
    """
    n = len(result.cases)
    fig = Figure(figsize=(10, 1.9 * n + 0.8), layout="constrained")
    axes = fig.subplots(n, 2, squeeze=False, width_ratios=(3, 2))
    for row, (label, resp) in zip(axes, result.cases.items(), strict=True):
        row[0].plot(resp.t, resp.r * MM, color="k", lw=0.9, label="r")
        row[0].plot(resp.t, resp.y * MM, color="C0", lw=1.1, label="y")
        row[0].set_ylabel(f"{label}\n[mm]", fontsize=8)
        row[1].plot(resp.t, resp.plant_error * MM, color="C3", lw=0.9)
        row[1].set_ylabel("r - y [mm]", fontsize=8)
        for ax in row:
            ax.grid(alpha=0.3)
            _mark_stop(ax, resp)
        if resp.y.size:
            lim = max(np.max(np.abs(resp.r)), 1e-9) * MM * 1.6
            row[0].set_ylim(-lim, lim)  # a diverging run would hide every other case
    axes[0, 0].legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("time [s]")
    axes[-1, 1].set_xlabel("time [s]")
    fig.suptitle(f"scheme {result.loop.scheme}, experiment {result.name}"
                 + (" (with DOB)" if result.loop.dob is not None else ""), fontsize=10)
    return fig


def plot_bode(f: np.ndarray, mag_db: np.ndarray, phase_deg: np.ndarray,
              margins: LoopMargins | None = None, title: str = "") -> Figure:
    """Magnitude and phase of the linearised open loop (fig. 7.4, 7.9) with the crossover.

    Parameters
    ----------
    f : numpy.ndarray, shape (n,)
        Frequency [Hz].
    mag_db : numpy.ndarray, shape (n,)
        Magnitude [dB].
    phase_deg : numpy.ndarray, shape (n,)
        Phase [deg].
    margins : LoopMargins, optional
        Marks the crossover and titles the margins when given.
    title : str, default ""
        Figure title (none when empty).

    Returns
    -------
    matplotlib.figure.Figure
        The two-panel figure.
    """
    fig = Figure(figsize=(7.5, 5.5), layout="constrained")
    ax_m, ax_p = fig.subplots(2, 1, sharex=True)
    ax_m.semilogx(f, mag_db, color="C0")
    ax_m.axhline(0, color="k", lw=0.8)
    ax_m.set_ylabel("|L| [dB]")
    ax_p.semilogx(f, phase_deg, color="C0")
    ax_p.axhline(-180, color="k", lw=0.8)
    ax_p.set_ylabel("arg L [deg]")
    ax_p.set_xlabel("frequency [Hz]")
    if margins is not None and margins.crossover_hz is not None:
        for ax in (ax_m, ax_p):
            ax.axvline(margins.crossover_hz, color="C3", lw=0.9, ls="--")
        ax_m.set_title(f"crossover {margins.crossover_hz:.3g} Hz, phase margin "
                       f"{margins.phase_margin_deg:.1f} deg, gain margin "
                       + ("inf" if margins.gain_margin_db is None
                          else f"{margins.gain_margin_db:.1f} dB")
                       + _closed_loop_words(margins),
                       fontsize=8)
    for ax in (ax_m, ax_p):
        ax.grid(alpha=0.3, which="both")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def _closed_loop_words(margins) -> str:
    """The title's second line for a loop that is not asymptotically stable, in the words of
    ``hystkit control`` (a mode slower than a slow cell is marginal, not UNSTABLE)."""
    if margins.closed_loop_stable:
        return ""
    if margins.growth_time_s is None:
        return ",\nclosed loop marginally stable (a pole on the unit circle)"
    if margins.slow_cell is not None:
        return (f",\nclosed loop marginal, from a slow cell of the {margins.slow_cell}: e-fold "
                f"in {margins.growth_time_s:.3g} s")
    return f",\nclosed loop UNSTABLE: e-fold growth in {margins.growth_time_s:.3g} s"
