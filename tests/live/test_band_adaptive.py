"""The band of an adapting stream follows the references (quantile tracking)."""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.compensation import fit_compensator, with_band
from hystkit.live import Adaptation, AdaptiveStream, Stream
from hystkit.sensors import simulate_experiment

EVERY = 40  # a reference every 40 samples (1 s at 40 Hz)


@pytest.fixture(scope="module")
def comp():
    train = simulate_experiment("noise", 1)
    return with_band(fit_compensator(train, 1, diagnose=False), [train], 1)


def _drifting(seed: int, gain_end: float) -> tuple[np.ndarray, np.ndarray]:
    """A run whose sensor gain rises linearly to `gain_end`, and its references."""
    rec = simulate_experiment("noise", seed)
    mid = float(np.mean(rec.sensor))
    gain = np.linspace(1.0, gain_end, rec.n_samples)
    reference = np.full(rec.n_samples, np.nan)
    reference[::EVERY] = rec.position[::EVERY]
    return mid + gain * (rec.sensor - mid), reference


def test_without_references_the_band_is_the_plain_streams(comp):
    sensor, _ = _drifting(2, 1.0)
    plain = Stream(comp).process_flagged(sensor)
    adapted = AdaptiveStream(comp).process_flagged(sensor)
    np.testing.assert_array_equal(adapted.lower, plain.lower)
    np.testing.assert_array_equal(adapted.upper, plain.upper)


@pytest.mark.parametrize("parameters", ["gain", "weights"])
def test_samples_and_chunks_give_the_same_band(comp, parameters):
    sensor, reference = _drifting(2, 1.3)
    n = 1200
    one = AdaptiveStream(comp, Adaptation(parameters))
    steps = [one.step_flagged(s, r) for s, r in zip(sensor[:n], reference[:n], strict=True)]
    chunked = AdaptiveStream(comp, Adaptation(parameters))
    parts = [chunked.process_flagged(s, r) for s, r in
             zip(np.array_split(sensor[:n], 5), np.array_split(reference[:n], 5), strict=True)]
    for name in ("estimate", "lower", "upper"):
        np.testing.assert_array_equal([getattr(s, name) for s in steps],
                                      np.concatenate([getattr(p, name) for p in parts]))
    assert one.state.n_band_checks == chunked.state.n_band_checks > 0


def test_the_band_recovers_its_coverage_under_drift(comp):
    """A sensor gain drifting to 1.5: the plain band misses far more references than its
    level allows by the end; the adapted band's share of misses over the run's second half is near 1 - level."""
    sensor, reference = _drifting(2, 1.5)
    rec = simulate_experiment("noise", 2)
    plain = Stream(comp).process_flagged(sensor)
    stream = AdaptiveStream(comp, Adaptation("gain"))
    adapted = stream.process_flagged(sensor, reference)
    late = np.zeros(sensor.size, dtype=bool)
    late[sensor.size // 2::EVERY] = True

    def missed(out):
        p = rec.position[late]
        return float(np.mean((p < out.lower[late]) | (p > out.upper[late])))

    # binomial tolerance: ~100 references in the second half
    tolerance = 3 * np.sqrt(0.1 * 0.9 / late.sum())
    assert missed(plain) > 0.1 + tolerance  # the calibrated band no longer holds
    assert abs(missed(adapted) - 0.1) <= tolerance
    assert stream.state.n_band_misses < stream.state.n_band_checks
