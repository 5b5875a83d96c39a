"""Compensator.estimate takes a plain array of sensor samples too (issue 27: it raised a raw
AttributeError), and refuses anything else in one clear TypeError."""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.compensation import fit_compensator
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def fitted():
    rec = simulate_experiment("sine", 1)
    return fit_compensator(rec, diagnose=False), rec


def test_an_array_of_sensor_samples_gives_the_recordings_estimate(fitted):
    comp, rec = fitted
    np.testing.assert_array_equal(comp.estimate(rec.sensor), comp.estimate(rec))
    np.testing.assert_array_equal(comp.estimate(list(rec.sensor[:50])), comp.estimate(rec)[:50])


@pytest.mark.parametrize("bad", [{"sensor": 1.0}, np.ones((3, 3)), ["a", "b"]])
def test_anything_else_is_one_clear_type_error(fitted, bad):
    comp, _ = fitted
    with pytest.raises(TypeError, match=r"estimate takes a Recording \(hystkit.read\(path\)\) "
                                        r"or a 1-D array of sensor samples taken every 0.025 s"):
        comp.estimate(bad)
