"""The generalisation heat map tells a good, a poor and a useless compensator apart (issue 11:
a linear colour scale clipped at 0.9 gave R² 0.876 and -2390 the same colour)."""

from __future__ import annotations

import matplotlib
import numpy as np

from hystkit.studies import plot_generalization

matplotlib.use("Agg")

MATRIX = {"mpl": {"r2": {"sine": {"sine": 0.999, "noise": 0.876},
                         "noise": {"sine": -2390.0, "noise": None}}},
          "pi": {"r2": {"sine": {"sine": 0.95, "noise": 0.5},
                        "noise": {"sine": 0.99, "noise": 0.999}}}}


def _colours(fig):
    image = fig.axes[0].images[0]
    return image, image.to_rgba(image.get_array())


def test_poor_and_useless_cells_get_different_colours():
    fig = plot_generalization(MATRIX)
    image, rgba = _colours(fig)
    good, poor, useless = rgba[0, 0], rgba[0, 1], rgba[1, 0]
    assert np.abs(poor - useless).max() > 0.2 and np.abs(good - poor).max() > 0.2
    # one log scale for all panels, reaching the worst value: 1 - R² = 2391
    assert image.norm.vmax == 2391.0 and fig.axes[1].images[0].norm is image.norm


def test_every_cell_shows_its_r2_and_failures_say_so():
    fig = plot_generalization(MATRIX)
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert texts == ["0.999", "0.876", "-2390.000", "fail"]
    assert np.ma.is_masked(fig.axes[0].images[0].get_array()[1, 1])


def _long_named_matrix() -> dict:
    """Four models on three recordings, one with a long file name (rows and columns)."""
    names = ["sine", "lab_run_2024-11-03_slow_sweep", "noise"]
    grid = {a: {b: 0.99 if a == b else 0.8 for b in names} for a in names}
    return {model: {"r2": grid} for model in ("mpl", "pi", "ladder", "preisach")}


def _drawn_boxes(fig):
    """Each axes' extent with its labels, title and tick labels (pixels), and the figure's."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    return [ax.get_tightbbox(renderer) for ax in fig.axes], fig.bbox, renderer


def test_labels_stay_in_the_figure_and_off_the_other_panels():
    # the layout is computed without drawing: check it against the drawn figure
    for matrix in (MATRIX, _long_named_matrix()):
        fig = plot_generalization(matrix)
        boxes, page, _ = _drawn_boxes(fig)
        assert len(boxes) == len(matrix) + 1  # the panels and the colour bar
        for box in boxes:
            assert page.x0 <= box.x0 and box.x1 <= page.x1
            assert page.y0 <= box.y0 and box.y1 <= page.y1
        for i, a in enumerate(boxes):
            assert not any(a.overlaps(b) for b in boxes[i + 1:])


def test_long_column_names_stand_upright_without_overlapping():
    fig = plot_generalization(_long_named_matrix())
    _, _, renderer = _drawn_boxes(fig)
    for ax in fig.axes[:-1]:
        labels = [t.get_window_extent(renderer) for t in ax.get_xticklabels()]
        assert all(t.get_rotation() == 90 for t in ax.get_xticklabels())
        assert not any(a.overlaps(b) for i, a in enumerate(labels) for b in labels[i + 1:])
    # short names stay level, as in the default four-excitation figure
    assert all(t.get_rotation() == 0 for t in plot_generalization(MATRIX).axes[0]
               .get_xticklabels())


def test_colour_bar_labels_each_decade_as_a_power_of_ten():
    fig = plot_generalization(MATRIX)  # 1 - R² from 1e-4 to 2391
    _drawn_boxes(fig)  # tick labels get their text when drawn
    bar = fig.axes[-1]
    shown = {round(np.log10(tick)): label.get_text()
             for tick, label in zip(bar.get_yticks(), bar.get_yticklabels())
             if bar.get_ylim()[0] <= tick <= bar.get_ylim()[1]}
    assert shown == {-4: "10⁻⁴", -3: "10⁻³", -2: "10⁻²", -1: "10⁻¹", 0: "10⁰", 1: "10¹",
                     2: "10²", 3: "10³"}
    assert bar.yaxis.get_minorticklocs().size == 0
