"""Fit-data preparation without full-length temporaries (issue 10), same numbers as before."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.compensation._conventions import LinearBaseline, prepare_training_data
from hystkit.io import Recording


def _recording(n: int, seed: int = 0) -> Recording:
    t = np.arange(n) * 0.025
    rng = np.random.default_rng(seed)
    phase = 2 * np.pi * 0.05 * t
    return Recording(time=t, position=3.0 + 10.0 * np.sin(phase),
                     sensor=0.5 - 0.02 * np.sin(phase - 0.3) + 1e-4 * rng.standard_normal(n))


@pytest.mark.parametrize("n", [3, 1000, 200_001])
def test_straight_line_is_polyfits(n: int) -> None:
    rng = np.random.default_rng(n)
    s = 0.3 * rng.standard_normal(n) + 0.01
    p = 2.0 * s - 0.02 + 0.1 * rng.standard_normal(n)
    line = LinearBaseline.fit(s, p)
    # both are least squares; they differ by summation order only
    assert_allclose([line.slope, line.intercept], np.polyfit(s, p, 1), rtol=1e-12)


@pytest.mark.parametrize("center", ["fit", "tare", "track", "recording", "none"])
def test_prepared_data_follow_the_conventions(center: str) -> None:
    recs = [_recording(4000, 1), _recording(2500, 2)]
    conventions, s_list, p_list = prepare_training_data(recs, center)
    scaling, polarity = conventions["scaling"], conventions["polarity"]
    s, p = np.concatenate(s_list), np.concatenate(p_list)
    assert polarity == -1.0  # the sensor falls as the position rises
    assert max(np.max(np.abs(s)), np.max(np.abs(p))) == 1.0  # scaled by the largest |value|
    assert np.corrcoef(s, p)[0, 1] > 0  # polarity makes the correlation positive
    # undo the conventions by hand: the recordings' own columns come back
    assert_allclose(np.concatenate([r.position for r in recs]),
                    p * scaling.position_scale + scaling.position_offset
                    + (np.repeat([np.mean(r.position) - scaling.position_offset for r in recs],
                                 [r.n_samples for r in recs]) if center == "recording" else 0),
                    rtol=1e-12)
    if center == "fit":
        assert_allclose(np.mean(s), 0.0, atol=1e-12)
        assert_allclose(np.mean(p), 0.0, atol=1e-12)


def test_preparation_allocates_only_its_outputs() -> None:
    rec = _recording(500_000)
    column = rec.sensor.nbytes
    tracemalloc.start()
    try:
        _conventions, _s, _p = prepare_training_data([rec], "fit")
        _current, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # the two normalised columns are the output; before issue 10's fix the peak was 9 columns
    assert peak < 2 * column + column // 10
