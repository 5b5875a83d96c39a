"""The figure helpers of the reports: envelope decimation, the zoom window, the axis labels."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.io import ReadOptions, Recording
from hystkit.studies._figures import (
    LOOP_COLUMNS,
    envelope_indices,
    plot_loops,
    plot_time_series,
    zoom_window,
)
from hystkit.studies._report_model import named_parameters
from hystkit.studies._report_page import sensor_label


def test_envelope_keeps_every_sample_of_a_short_run() -> None:
    assert_array_equal(envelope_indices([np.arange(500.0)], max_points=500), np.arange(500))


@pytest.mark.parametrize("n", [20_001, 123_457, 1_000_000])
def test_envelope_keeps_every_extreme_and_few_points(n: int) -> None:
    rng = np.random.default_rng(n)
    a = np.cumsum(rng.normal(size=n))
    b = rng.normal(size=n)
    b[n // 3] = 50.0   # one-sample spikes a stride would skip
    b[n // 3 + 1] = -50.0
    keep = envelope_indices([a, b], max_points=4000)
    assert keep.size <= 4000 + 2
    assert np.all(np.diff(keep) > 0) and keep[0] == 0 and keep[-1] == n - 1
    for values in (a, b):
        assert values[keep].max() == values.max() and values[keep].min() == values.min()
    # each bin's extremes: the largest value of any stretch of one bin width is kept
    width = -(-n // (4000 // 4))
    for start in range(0, n, width):
        block = b[start:start + width]
        kept = b[keep[(keep >= start) & (keep < start + width)]]
        assert kept.max() == block.max() and kept.min() == block.min()


def test_zoom_window_is_centred_on_the_largest_error_inside_the_run() -> None:
    t = np.arange(1000) * 0.01
    error = np.zeros(1000)
    error[700] = -3.0
    assert zoom_window(t, error) == (650, 750)
    error[700], error[5] = 0.0, 2.0   # near the start: shifted to begin at 0
    assert zoom_window(t, error) == (0, 100)
    error[5], error[998] = 0.0, 2.0   # near the end: shifted to end at the last sample
    assert zoom_window(t, error) == (900, 1000)
    assert zoom_window(t[:15], error[:15]) == (0, 15)   # shorter than 20 samples: all of it


def test_named_parameters_follow_the_order_of_the_fit_vector() -> None:
    params = {"i_s": [0.1, 0.2], "v_t": [0.5, 0.6], "w": [1.0, -1.0, 0.5], "v_b": -0.01,
              "n": 3, "nested": {"a": [[1.0, 2.0], [3.0]]}}
    assert named_parameters(params) == [
        ("i_s[0]", 0.1), ("i_s[1]", 0.2), ("v_t[0]", 0.5), ("v_t[1]", 0.6), ("w[0]", 1.0),
        ("w[1]", -1.0), ("w[2]", 0.5), ("v_b", -0.01), ("nested.a[0][0]", 1.0),
        ("nested.a[0][1]", 2.0), ("nested.a[1][0]", 3.0)]


def _results(n: int = 400) -> dict:
    t = np.arange(n) * 0.025
    p = 3 * np.sin(2 * np.pi * 0.5 * t)
    rec = Recording(time=t, sensor=0.05 * p + 0.01 * np.cos(2 * np.pi * 0.5 * t), position=p)
    return {"run": (rec, p + 0.1, 1.1 * p)}


def test_loops_show_the_error_and_label_the_sensor_as_given() -> None:
    results = _results()
    fig = plot_loops(results, sensor_label="resistance_ohm")
    axes = fig.axes
    assert [ax.get_ylabel() for ax in axes] == ["resistance_ohm", "estimate [mm]",
                                                "estimate − position [mm]"]
    # the error panel draws estimate - position exactly (0.1 for the model, 0.1 p for the line)
    rec, estimate, linear = results["run"]
    lines = {tuple(np.round(line.get_ydata()[:3], 12)) for line in axes[2].get_lines()}
    assert tuple(np.round((estimate - rec.position)[:3], 12)) in lines
    assert tuple(np.round((linear - rec.position)[:3], 12)) in lines
    assert not any(ax.get_legend() for ax in axes)  # the legend is the figure's, outside
    assert len(fig.legends) == 1
    assert "ΔR1/R1" not in plot_loops(results).axes[0].get_ylabel()


def test_time_series_covers_the_whole_run() -> None:
    results = _results(4000)   # 100 s
    fig = plot_time_series(results)
    full = fig.axes[0]
    x = np.concatenate([line.get_xdata() for line in full.get_lines()])
    rec = results["run"][0]
    assert x.min() == rec.time[0] and x.max() == rec.time[-1]


def test_sensor_label_names_the_users_column_and_unit() -> None:
    t = np.arange(10) * 0.1
    plain = Recording(time=t, sensor=t, position=t)
    assert sensor_label(None, [plain]) == "sensor"
    own = ReadOptions(columns={"sensor": "resistance_ohm"})
    assert sensor_label(own, [plain]) == "resistance_ohm"
    if "units" not in Recording.__dataclass_fields__:
        pytest.skip("recordings carry no units in this version")
    ohm = Recording(time=t, sensor=t, position=t, units={"sensor": "Ohm"})
    volt = Recording(time=t, sensor=t, position=t, units={"sensor": "V"})
    assert sensor_label(own, [ohm, ohm]) == "resistance_ohm [Ohm]"
    assert sensor_label(None, [ohm]) == "sensor [Ohm]"
    assert sensor_label(own, [ohm, volt]) == "resistance_ohm"  # no common unit: none shown


def test_many_recordings_wrap_into_bands_of_loop_columns() -> None:
    run = _results()["run"]
    results = {f"r{k}": run for k in range(LOOP_COLUMNS + 2)}
    fig = plot_loops(results)
    visible = [ax for ax in fig.axes if ax.axison]
    assert len(visible) == 3 * len(results)
    assert [ax.get_title() for ax in visible if ax.get_title().endswith(": sensor")] == [
        f"r{k}: sensor" for k in range(LOOP_COLUMNS + 2)]
    assert fig.get_size_inches()[0] == pytest.approx(3.4 * LOOP_COLUMNS)


def test_position_axes_carry_the_files_unit_else_mm() -> None:
    """A recording in µm is drawn in µm (the tutorial's piezo excerpts); one without units in
    hystkit's mm."""
    rec, estimate, linear = _results()["run"]
    microns = Recording(time=rec.time, sensor=rec.sensor, position=rec.position,
                        units={"position": "µm", "sensor": "V"})
    for run, unit in ((rec, "mm"), (microns, "µm")):
        results = {"run": (run, estimate, linear)}
        loops = plot_loops(results).axes
        assert [ax.get_xlabel() for ax in loops] == [f"position [{unit}]"] * 3
        assert loops[1].get_ylabel() == f"estimate [{unit}]"
        series = plot_time_series(results).axes
        assert series[0].get_ylabel() == unit
        assert series[2].get_ylabel() == f"estimate − position [{unit}]"  # row 2, left
