"""The generalisation heat map tells a good, a poor and a useless compensator apart (issue 11:
a linear colour scale clipped at 0.9 gave R² 0.876 and -2390 the same colour)."""

from __future__ import annotations

import matplotlib
import numpy as np

from hystkit.reports import plot_generalization

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
