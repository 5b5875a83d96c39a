"""Figures of a compensation result. Each returns its Figure; nothing is shown or styled globally.

Both figures take ``{name: (recording, estimate, linear estimate)}``: the compensator's and the
straight line's position estimates on each recording, in the position's unit (the file's, else
mm). The error shown is the estimate minus the measured position, as the compensator delivers
it (no mean removed). Long recordings are
drawn through :func:`envelope_indices`, which keeps every bin's extremes, so a spike still shows.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from ..io import Recording

__all__ = ["DEFAULT_SENSOR_LABEL", "LOOP_COLUMNS", "MAX_POINTS", "envelope_indices", "plot_loops",
           "plot_time_series", "zoom_window"]

DEFAULT_SENSOR_LABEL = "sensor"
LOOP_COLUMNS = 4  # recordings side by side in the loop figure: readable at a page's width
# Points per drawn trace: beyond this a line is drawn through its per-bin minima and maxima.
MAX_POINTS = 20_000
# Trace colours, shared by both figures so a legend reads the same in each.
_COLORS = {"position": "k", "line": "tab:blue", "model": "tab:orange", "sensor": "tab:purple"}

Results = Mapping[str, tuple[Recording, np.ndarray, np.ndarray]]


def envelope_indices(arrays: Sequence[np.ndarray], max_points: int = MAX_POINTS) -> np.ndarray:
    """Sample indices that keep the shape of every array in `arrays` with few points.

    With ``n <= max_points`` samples, all of them. Otherwise the run is cut into equal bins and
    each bin contributes the positions of its minimum and maximum in every array (and the first
    and last sample are kept): a line through these samples reaches every extreme the full data
    reach, which plain striding would skip.

    Returns
    -------
    ndarray of int, sorted and unique
    """
    n = len(arrays[0])
    if n <= max_points:
        return np.arange(n)
    n_bins = max(1, max_points // (2 * len(arrays)))
    width = -(-n // n_bins)  # ceil: the last bin may be short
    kept = [np.array([0, n - 1])]
    for values in arrays:
        padded = np.full(n_bins * width, np.nan)
        padded[:n] = values
        blocks = padded.reshape(n_bins, width)
        valid = ~np.all(np.isnan(blocks), axis=1)
        offsets = np.arange(n_bins)[valid] * width
        kept.append(offsets + np.nanargmin(blocks[valid], axis=1))
        kept.append(offsets + np.nanargmax(blocks[valid], axis=1))
    return np.unique(np.concatenate(kept))


def zoom_window(time: np.ndarray, error: np.ndarray, fraction: float = 0.1) -> tuple[int, int]:
    """``(start, stop)`` sample slice of `fraction` of the run centred on the largest |error|,
    shifted to lie inside the run (the whole run if it is shorter than 20 samples)."""
    n = len(time)
    width = max(20, round(fraction * n))
    if width >= n:
        return 0, n
    centre = int(np.argmax(np.abs(error)))
    start = min(max(0, centre - width // 2), n - width)
    return start, start + width


def _legend_below(fig: Figure, ax) -> None:
    """One legend for the figure, outside every axes so it covers no trace."""
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncols=len(labels),
               fontsize="small", frameon=False)


def plot_loops(results: Results, *, sensor_label: str = DEFAULT_SENSOR_LABEL,
               model_label: str = "mPL") -> Figure:
    """Hysteresis loops before and after compensation and the error, one column per recording
    (at most `LOOP_COLUMNS` side by side; more recordings continue in a further band below).

    Rows: the sensor against the position (the loop to remove); both estimates against the
    position with the ideal diagonal; the error (estimate - position) against the position.

    Parameters
    ----------
    results : mapping name -> (recording, estimate [mm], linear estimate [mm])
    sensor_label : str
        The sensor axis' label: the sensor's name and unit where known.
    model_label : str
        The compensator's name in the legend.

    Returns
    -------
    matplotlib.figure.Figure
        Three rows per band of recordings.
    """
    n_cols = min(len(results), LOOP_COLUMNS)
    n_bands = -(-len(results) // n_cols)
    fig = Figure(figsize=(3.4 * max(n_cols, 2), 8.4 * n_bands), layout="constrained")
    axes = fig.subplots(3 * n_bands, n_cols, squeeze=False)
    for ax in axes[3 * (n_bands - 1):, len(results) - (n_bands - 1) * n_cols:].ravel():
        ax.set_axis_off()  # the last band's empty columns
    for k, (name, (rec, estimate, linear)) in enumerate(results.items()):
        p = rec.position
        errors = (linear - p, estimate - p)
        keep = envelope_indices([p, rec.sensor, *errors])
        band, col = divmod(k, n_cols)
        top, mid, low = axes[3 * band:3 * band + 3, col]
        top.plot(p[keep], rec.sensor[keep], lw=0.6, color=_COLORS["sensor"])
        unit = _position_unit(rec)
        top.set(title=f"{name}: sensor", xlabel=f"position [{unit}]", ylabel=sensor_label)
        lo, hi = float(p.min()), float(p.max())
        mid.plot([lo, hi], [lo, hi], color="k", lw=0.8, ls="--", label="ideal")
        for (label, key), values in zip((("straight line", "line"), (model_label, "model")),
                                        (linear, estimate)):
            alpha = 0.6 if key == "line" else 1.0
            mid.plot(p[keep], values[keep], lw=0.6, color=_COLORS[key], alpha=alpha,
                     label=label)
        mid.set(title=f"{name}: compensated", xlabel=f"position [{unit}]",
                ylabel=f"estimate [{unit}]")
        low.axhline(0.0, color="k", lw=0.8, ls="--")
        for key, values in zip(("line", "model"), errors):
            low.plot(p[keep], values[keep], lw=0.6, color=_COLORS[key],
                     alpha=0.6 if key == "line" else 1.0)
        low.set(title=f"{name}: error", xlabel=f"position [{unit}]",
                ylabel=f"estimate − position [{unit}]")
    _legend_below(fig, axes[1, 0])
    return fig


def plot_time_series(results: Results, *, model_label: str = "mPL",
                     bands: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
                     band_label: str = "band") -> Figure:
    """Measured and estimated position and the error over the whole of each recording, with a
    zoom on the stretch around the compensator's largest error.

    Two rows per recording (positions; errors), the full run on the left and the zoom
    (:func:`zoom_window`) on the right.

    Parameters
    ----------
    results : mapping of str to (Recording, numpy.ndarray, numpy.ndarray)
        Per recording name: the recording, the estimate [mm] and the linear estimate [mm].
    model_label : str, default "mPL"
        The compensator's name in the legend.
    bands : mapping of str to (numpy.ndarray, numpy.ndarray), optional
        Per recording name: the estimate's prediction band (lower, upper) [mm], shaded around
        the estimate and, in the error panel, around the error (covered where it holds 0).
    band_label : str, default "band"
        The band's name in the legend.

    Returns
    -------
    matplotlib.figure.Figure
        Two rows per recording.
    """
    n = len(results)
    fig = Figure(figsize=(12.0, 3.6 * n + 0.6), layout="constrained")
    axes = fig.subplots(2 * n, 2, squeeze=False, width_ratios=(3, 1))
    for k, (name, (rec, estimate, linear)) in enumerate(results.items()):
        t, p, unit = rec.time, rec.position, _position_unit(rec)
        error, line_error = estimate - p, linear - p
        start, stop = zoom_window(t, error)
        for col, span in enumerate((slice(None), slice(start, stop))):
            top, low = axes[2 * k, col], axes[2 * k + 1, col]
            tt = t[span]
            series = (p[span], linear[span], estimate[span], line_error[span], error[span])
            band = None if bands is None or name not in bands else tuple(
                b[span] for b in bands[name])
            keep = envelope_indices(series + (band or ()))
            if band is not None:
                top.fill_between(tt[keep], band[0][keep], band[1][keep], color=_COLORS["model"],
                                 alpha=0.2, lw=0, label=band_label)
                low.fill_between(tt[keep], (band[0] - p[span])[keep], (band[1] - p[span])[keep],
                                 color=_COLORS["model"], alpha=0.2, lw=0)
            top.plot(tt[keep], series[0][keep], color=_COLORS["position"], lw=1.0,
                     label="position")
            top.plot(tt[keep], series[1][keep], color=_COLORS["line"], lw=0.8, alpha=0.6,
                     label="straight line")
            top.plot(tt[keep], series[2][keep], color=_COLORS["model"], lw=0.8,
                     label=model_label)
            low.axhline(0.0, color="k", lw=0.6, ls="--")
            low.plot(tt[keep], series[3][keep], color=_COLORS["line"], lw=0.7, alpha=0.6)
            low.plot(tt[keep], series[4][keep], color=_COLORS["model"], lw=0.7)
            low.set_xlabel("time [s]")
            if col == 0:
                top.set(title=f"{name}: whole run ({t[-1] - t[0]:.4g} s)", ylabel=unit)
                low.set(title=f"{name}: error", ylabel=f"estimate − position [{unit}]")
            else:
                top.set_title(f"zoom: largest {model_label} error, "
                              f"t = {t[start]:.4g}–{t[stop - 1]:.4g} s", fontsize="small")
    _legend_below(fig, axes[0, 0])
    return fig


def _position_unit(rec) -> str:
    """The position's unit as the recording's file gave it; mm (hystkit's convention) when the
    file gave none."""
    return rec.unit("position") or "mm"
