"""The figure of ``hystkit generalize``: one heat map of R² per model, laid out without an
extra drawing of the figure."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # matplotlib loads in plot_generalization: generalize without a figure, and
    # compare, which imports this name, draw nothing (~0.3 s)
    from matplotlib.figure import Figure

__all__ = ["plot_generalization"]


def plot_generalization(matrix: Mapping[str, dict]) -> Figure:
    """One heat map per model: rows = trained on, columns = tested on, each cell's R² written
    in it. The colour is the unexplained fraction 1 - R² on a log scale shared by all panels,
    so 0.99, 0.876 and -2390 all look different (a linear scale clipped at 0.9 made the last
    two alike); failed cells stay blank.

    Parameters
    ----------
    matrix : mapping of str to dict
        :func:`generalization_matrix`'s result (its ``"r2"`` grids are drawn).

    Returns
    -------
    matplotlib.figure.Figure
        Up to three panels a row, one per model, with a shared colour bar on the right.
    """
    from matplotlib.colors import LogNorm
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter

    grids = {name: _r2_grid(entry["r2"]) for name, entry in matrix.items()}
    layout = _PanelLayout.fit(
        len(matrix), [label for rows, _, _ in grids.values() for label in rows],
        [label for _, names, _ in grids.values() for label in names],
        max((len(names) for _, names, _ in grids.values()), default=1))
    fig = Figure(figsize=layout.figsize)
    worst = max([np.nanmax(1 - v) for _, _, v in grids.values() if np.isfinite(v).any()],
                default=1.0)
    norm = LogNorm(vmin=_UNEXPLAINED_FLOOR, vmax=max(1.0, worst))
    image = None
    for k, (name, (rows, names, values)) in enumerate(grids.items()):
        ax = fig.add_axes(layout.panel(k))
        unexplained = np.clip(1 - values, _UNEXPLAINED_FLOOR, None)
        image = ax.imshow(unexplained, norm=norm, cmap="viridis_r")
        for i in range(len(rows)):
            for j in range(len(names)):
                failed = np.isnan(values[i, j])
                dark = not failed and norm(unexplained[i, j]) > 0.6  # viridis_r: dark when bad
                ax.text(j, i, "fail" if failed else f"{values[i, j]:.3f}", ha="center",
                        va="center", fontsize="small", color="w" if dark else "k")
        ax.set(xticks=range(len(names)), xticklabels=names, yticks=range(len(rows)),
               yticklabels=rows, xlabel="tested on", ylabel="trained on",
               title=f"{name} (deployable R²)")
        ax.tick_params(axis="x", labelrotation=layout.column_rotation)
    if image is not None:
        bar = fig.colorbar(image, cax=fig.add_axes(layout.colour_bar()),
                           label="1 - R² (log scale)\n1: no better than the mean")
        # Decades as plain text (10⁻⁴), without minor ticks: matplotlib's default 10^-4 labels
        # set up its maths typesetter, ~0.14 s of the figure's first drawing, and its minor
        # ticks ~0.08 s more
        bar.ax.yaxis.set_major_formatter(FuncFormatter(_decade_label))
        bar.minorticks_off()
    return fig


_SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _decade_label(value: float, _position: int) -> str:
    """``10⁻⁴`` for 1e-4 and the other powers of ten; nothing between them."""
    exponent = round(np.log10(value)) if value > 0 else None
    if exponent is None or not np.isclose(value, 10.0 ** exponent, rtol=1e-9):
        return ""
    return "10" + str(exponent).translate(_SUPERSCRIPTS)


class _PanelLayout:
    """Where the generalisation figure's panels and colour bar go, worked out once from the
    fonts' sizes and the longest recording names (no drawing): up to three panels a row, each
    a 2.7 x 2.2 in axes box (the image square inside it) with room for its labels, and the
    colour bar on the right. Matplotlib's constrained layout found such places by drawing the
    figure an extra time: ~0.5 s of the ~1 s that saving the 10-model figure took, serial work
    after ``generalize``'s parallel map."""

    AXES = (2.7, 2.2)  # inches of a panel's axes box; the labels go around it
    BAR_SPACE = 1.4  # inches right of the panels: the colour bar, its ticks and its label
    PAD = 0.1  # inches between a panel's labels and the next panel or the figure's edge

    def __init__(self, n_panels: int, margins: tuple[float, float, float],
                 column_rotation: float):
        self.n_cols = min(3, max(n_panels, 1))
        self.n_rows = max(-(-n_panels // self.n_cols), 1)
        self.left, self.bottom, self.top = margins
        self.column_rotation = column_rotation
        self.cell = (self.left + self.AXES[0] + self.PAD, self.bottom + self.AXES[1] + self.top)
        self.figsize = (self.cell[0] * self.n_cols + self.BAR_SPACE, self.cell[1] * self.n_rows)

    @classmethod
    def fit(cls, n_panels: int, row_labels: Sequence[str], column_labels: Sequence[str],
            n_columns: int) -> _PanelLayout:
        """Margins that hold the longest of `row_labels` (tick labels left of a panel) and of
        `column_labels` (below it, turned upright when wider than a column of `n_columns`)."""
        import matplotlib as mpl
        from matplotlib.font_manager import FontProperties
        from matplotlib.textpath import TextToPath

        rc, measure = mpl.rcParams, TextToPath()

        def extent(texts: Sequence[str], size: str | float) -> tuple[float, float]:
            """Widest width and one line's height of `texts` at font `size` [points]."""
            font = FontProperties(size=size)
            widths = [measure.get_text_width_height_descent(t, font, ismath=False)[0]
                      for t in texts]
            line = measure.get_text_width_height_descent("Tg", font, ismath=False)[1] * 1.2
            return max(widths, default=0.0), line

        label = extent([], rc["axes.labelsize"])[1] + rc["axes.labelpad"]
        ticks = max(rc["ytick.major.size"], rc["xtick.major.size"]) + max(
            rc["ytick.major.pad"], rc["xtick.major.pad"])
        row_width, _ = extent(row_labels, rc["ytick.labelsize"])
        column_width, line = extent(column_labels, rc["xtick.labelsize"])
        # A column's share of the image (square cells in the axes box's height) [points]
        upright = column_width > 0.9 * 72 * cls.AXES[1] / max(n_columns, 1)
        bottom = label + ticks + (column_width if upright else line)
        top = extent([], rc["axes.titlesize"])[1] + rc["axes.titlepad"]
        margins = (cls.PAD + (label + ticks + row_width) / 72, cls.PAD + bottom / 72,
                   cls.PAD + top / 72)
        return cls(n_panels, margins, 90.0 if upright else 0.0)

    def panel(self, k: int) -> tuple[float, float, float, float]:
        """Axes rectangle (left, bottom, width, height; figure fractions) of panel `k`, row by
        row from the top left."""
        (width, height), (cell_w, cell_h) = self.figsize, self.cell
        x0 = (k % self.n_cols) * cell_w + self.left
        y0 = (self.n_rows - 1 - k // self.n_cols) * cell_h + self.bottom
        return x0 / width, y0 / height, self.AXES[0] / width, self.AXES[1] / height

    def colour_bar(self) -> tuple[float, float, float, float]:
        """The colour bar's rectangle: 0.2 in wide, 80 % of the figure's height, centred."""
        width = self.figsize[0]
        return (self.cell[0] * self.n_cols + 0.25) / width, 0.1, 0.2 / width, 0.8


# 1 - R² below this (R² above 0.9999) shows as the best colour
_UNEXPLAINED_FLOOR = 1e-4


def _r2_grid(grid: Mapping[str, Mapping[str, float | None]]) -> tuple[list, list, np.ndarray]:
    """Row names, column names and the R² values of one model (NaN where it failed)."""
    rows = list(grid)
    names = list(next(iter(grid.values()))) if grid else []
    values = np.array([[np.nan if grid[a][b] is None else grid[a][b] for b in names]
                       for a in rows], dtype=float).reshape(len(rows), len(names))
    return rows, names, values
