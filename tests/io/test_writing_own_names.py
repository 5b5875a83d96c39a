"""A recording written in its file's own names and time unit (issue 27, item 4): the values
as the file holds them, and read back, with the settings written beside a CSV, to the same
recording bit for bit."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_array_equal
from scipy.io import loadmat

from hystkit.io import ReadOptions, options_for, read_recording, write_recording
from hystkit.io._writing import time_in_unit

NAMES = {"time": "t_ms", "position": "x_mm", "sensor": "R_ohm"}


@pytest.fixture
def rec(tmp_path):
    """A recording read from a file in ms, as a lab writes it (steps of 25 ms)."""
    path = tmp_path / "in.csv"
    pd.DataFrame({"t_ms": np.arange(400) * 25.0, "x_mm": np.sin(np.arange(400) / 7),
                  "R_ohm": np.cos(np.arange(400) / 5)}).to_csv(path, index=False)
    return read_recording(path, options=ReadOptions(columns=NAMES, time_unit="ms",
                                                    units={"position": "mm"}))


def test_csv_in_the_inputs_names_reads_back_to_the_same_recording(rec, tmp_path):
    out = write_recording(rec, tmp_path / "out.csv", names=NAMES, time_unit="ms",
                          units_sidecar=True)
    written = pd.read_csv(out)
    assert list(written.columns) == ["t_ms", "x_mm", "R_ohm"]
    assert_array_equal(written["t_ms"].to_numpy(), np.arange(400) * 25.0)  # ms, as read
    options, settings = options_for(out)
    assert settings == tmp_path / "out.toml"
    assert options.columns == tuple(NAMES.items()) and options.time_unit == "ms"
    back = read_recording(out, options=options)
    for name in ("time", "position", "sensor"):
        assert_array_equal(getattr(back, name), getattr(rec, name))
    assert dict(back.units) == {"position": "mm"}


def test_mat_names_and_units(rec, tmp_path):
    out = write_recording(rec, tmp_path / "out.mat", names=NAMES, time_unit="ms")
    m = loadmat(out, simplify_cells=True)
    assert list(m["column_names"]) == ["t_ms", "x_mm", "R_ohm"]
    assert m["units"] == {"t_ms": "ms", "x_mm": "mm"}
    assert_array_equal(m["t_ms"], np.arange(400) * 25.0)


def test_hystkits_names_in_seconds_are_written_as_before(rec, tmp_path):
    out = write_recording(rec, tmp_path / "out.csv", units_sidecar=True)
    written = pd.read_csv(out)
    assert list(written.columns) == ["time", "position", "sensor"]
    assert_array_equal(written["time"].to_numpy(), rec.time)
    assert "[columns]" not in (tmp_path / "out.toml").read_text(encoding="utf-8")


@pytest.mark.parametrize("unit, step", [("ms", 25.0), ("us", 125.0), ("ns", 7.0),
                                        ("min", 0.5), ("ms", 0.1)])
def test_time_in_unit_reads_back_to_the_same_seconds(unit, step):
    scale = {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "min": 60.0}[unit]
    raw = np.arange(100_000) * step
    seconds = raw * scale  # as the reader converts
    values = time_in_unit(seconds, unit)
    assert_array_equal(values * scale, seconds)  # exact: the file reads back bit for bit
    if float(step).is_integer():  # whole numbers in the file come back as written
        assert_array_equal(values, raw)
