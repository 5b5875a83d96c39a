"""The prediction band: calibrated on held-out runs, causal, wider where the model extrapolates."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from hystkit.compensation import (
    fit_compensator,
    interval_scores,
    load_compensator,
    save_compensator,
    with_band,
)
from hystkit.compensation._band import QUANTILE_GRID, Band, band_features, local_scale
from hystkit.errors import InputError
from hystkit.io import Recording
from hystkit.live import Stream
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def banded():
    """A 1-cell mPL with its band, fitted on the virtual sensor's sine, run 1."""
    train = simulate_experiment("sine", 1)
    return with_band(fit_compensator(train, 1, diagnose=False), [train], 1), train


def _recording(rec: Recording, sensor: np.ndarray, position: np.ndarray | None = None):
    return Recording(time=rec.time[:sensor.size], sensor=sensor,
                     position=rec.position[:sensor.size] if position is None else position,
                     source="edited")


def test_coverage_on_new_runs_of_the_same_excitation_is_nominal(banded):
    """Exchangeable data (other runs, other noise): coverage >= 0.90 within a binomial
    tolerance that counts one independent sample per memory time constant of the errors."""
    comp, _ = banded
    for seed in (2, 3, 4):
        test = simulate_experiment("sine", seed)
        _, lower, upper = comp.estimate_with_band(test)
        coverage = interval_scores(test.position, lower, upper, 0.9)["band_coverage"]
        n_independent = test.n_samples * test.dt / comp.band.tau
        assert coverage >= 0.9 - 3 * math.sqrt(0.9 * 0.1 / n_independent), seed


def test_the_band_is_useful_not_just_wide(banded):
    """Where the model works, the half-width is within 3 times its RMS error."""
    comp, _ = banded
    test = simulate_experiment("sine", 2)
    est, lower, upper = comp.estimate_with_band(test)
    rms = np.sqrt(np.mean((est - test.position) ** 2))
    assert np.median(upper - lower) / 2 <= 3 * rms


def test_level_orders_the_bands(banded):
    comp, train = banded
    widths = [np.median(np.diff(comp.estimate_with_band(train, level)[1:], axis=0))
              for level in (0.5, 0.9, 0.99)]
    assert widths[0] < widths[1] < widths[2]


def test_band_is_causal(banded):
    """Changing future sensor samples or the position column changes nothing up to now."""
    comp, train = banded
    k = 3000
    base = comp.estimate_with_band(train)
    future = train.sensor.copy()
    future[k:] = future[k:] * 3 + 1
    changed = comp.estimate_with_band(_recording(train, future))
    np.testing.assert_array_equal(changed.lower[:k], base.lower[:k])
    np.testing.assert_array_equal(changed.upper[:k], base.upper[:k])
    moved = comp.estimate_with_band(_recording(train, train.sensor, train.position + 5.0))
    np.testing.assert_array_equal(moved.lower, base.lower)
    np.testing.assert_array_equal(moved.upper, base.upper)


def test_chunks_continue_exactly(banded):
    """The features of a recording in chunks equal the whole run's, bit for bit."""
    comp, train = banded
    s = comp.normalised_sensor(train.sensor)
    whole = band_features(s, train.dt, comp.band.tau, comp.training_range)
    state, rates, outs = None, [], []
    for chunk in np.array_split(s, [1, 7, 500, 4001]):
        rate, out, state = band_features(chunk, train.dt, comp.band.tau, comp.training_range,
                                         state)
        rates.append(rate)
        outs.append(out)
    np.testing.assert_array_equal(np.concatenate(rates), whole[0])
    np.testing.assert_array_equal(np.concatenate(outs), whole[1])


def test_band_widens_outside_the_training_range(banded):
    """A sensor driven to twice its training amplitude: the band widens by at least the
    extrapolated distance where it is outside."""
    comp, train = banded
    inside = comp.estimate_with_band(train)
    mid = np.median(train.sensor)
    wide = _recording(train, mid + 2.0 * (train.sensor - mid))
    outside = comp.estimate_with_band(wide)
    mask = comp.sensor_outside(wide)
    assert mask.mean() > 0.2
    width_in, width_out = (np.median((b.upper - b.lower)[mask]) for b in (inside, outside))
    assert width_out > 2 * width_in


def test_band_widens_beyond_the_fastest_training_rate(banded):
    """The same sine at four times the rate (every 4th sample): sigma at least doubles."""
    comp, train = banded
    fast = train.sensor[::4]
    s = comp.normalised_sensor(fast)
    rate, _, _ = band_features(s, train.dt, comp.band.tau, comp.training_range)
    late = slice(s.size // 2, None)  # after the running mean has settled
    assert np.median(local_scale(comp.band, rate[late])) >= 2.0


def test_interval_score_closed_form():
    position = np.array([0.0, 1.0, 5.0])
    lower, upper = np.array([-1.0, 2.0, 0.0]), np.array([1.0, 3.0, 4.0])
    scores = interval_scores(position, lower, upper, 0.8)
    assert scores["band_coverage"] == pytest.approx(1 / 3)
    # widths 2, 1, 4; misses 0, 1 below, 1 above; 2 / (1 - 0.8) = 10
    assert scores["interval_score"] == pytest.approx((2 + 1 + 4 + 10 + 10) / 3)
    assert scores["band_width_median"] == 2.0


def test_quantile_uses_the_finite_sample_correction():
    band = Band(0.9, tuple(QUANTILE_GRID * 10), 9, 1.0, 1.0, 2.0, 0.0, "p")
    # ceil(10 * 0.9) / 9 = 1: the largest score
    assert band.quantile() == pytest.approx(10.0)
    assert band.quantile(0.5) == pytest.approx(10 * math.ceil(10 * 0.5) / 9)


@pytest.mark.parametrize("suffix", [".json", ".mat"])
def test_model_file_keeps_the_band(banded, tmp_path, suffix):
    comp, train = banded
    path = save_compensator(comp, tmp_path / f"m{suffix}")
    back = load_compensator(path)
    assert back.band == comp.band
    np.testing.assert_array_equal(back.estimate_with_band(train).upper,
                                  comp.estimate_with_band(train).upper)


@pytest.mark.parametrize(("key", "value", "says"), [
    ("rate_share", 2.0, "rate_share"),
    ("level", 1.5, "level"),
    ("tau", -1.0, "band.tau"),
    ("n_calibration", 0, "band.n_calibration"),
    ("protocol", 3, "band.protocol"),
])
def test_tampered_band_is_refused_naming_the_key(banded, tmp_path, key, value, says):
    comp, _ = banded
    path = save_compensator(comp, tmp_path / "m.json")
    d = json.loads(path.read_text())
    d["band"][key] = value
    path.write_text(json.dumps(d))
    with pytest.raises(InputError, match=says):
        load_compensator(path)


def test_decreasing_quantiles_are_refused(banded, tmp_path):
    comp, _ = banded
    path = save_compensator(comp, tmp_path / "m.json")
    d = json.loads(path.read_text())
    d["band"]["quantiles"][5] = -1.0
    path.write_text(json.dumps(d))
    with pytest.raises(InputError, match=r"band\.quantiles\[5\]"):
        load_compensator(path)


def test_without_a_band_the_estimate_still_works_and_the_band_says_why(banded):
    comp, train = banded
    bare = replace(comp, band=None)
    assert bare.estimate(train).shape == train.position.shape
    with pytest.raises(InputError, match="no band"):
        bare.estimate_with_band(train)


def test_several_recordings_calibrate_on_left_out_recordings():
    runs = [simulate_experiment("sine", seed) for seed in (1, 2)]
    comp = with_band(fit_compensator(runs, 1, diagnose=False), runs, 1)
    assert comp.band.protocol == "left-out recording"
    assert comp.band.n_calibration == sum(r.n_samples for r in runs)
    assert "left-out recording" in comp.fit_info["band"]


@pytest.mark.parametrize("center", ["fit", "tare", "track"])
def test_stream_gives_the_offline_band_bit_for_bit(center):
    """Sample by sample and in chunks, the stream's band is the offline band exactly."""
    train = simulate_experiment("noise", 1)
    comp = with_band(fit_compensator(train, 1, center=center, diagnose=False), [train], 1)
    test = simulate_experiment("sine", 2)
    offline = comp.estimate_with_band(test, 0.8)
    stream = Stream(comp, level=0.8)
    steps = [stream.step_flagged(v) for v in test.sensor[:300]]
    chunks = [stream.process_flagged(c) for c in np.array_split(test.sensor[300:], 7)]
    for name in ("lower", "upper"):
        got = np.concatenate([[getattr(s, name) for s in steps],
                              *[getattr(c, name) for c in chunks]])
        np.testing.assert_array_equal(got, getattr(offline, name))


def test_rate_share_is_scipys_nnls():
    """The two-coefficient NNLS written out equals scipy.optimize.nnls (random cases, both
    constraints active in some)."""
    from scipy.optimize import nnls

    from hystkit.compensation._calibration import MAX_RATE_SHARE, _rate_share

    rng = np.random.default_rng(0)
    for _ in range(200):
        rate = rng.random(300) * rng.random() * 5
        error = np.abs(rng.normal(rng.normal(), 1, 300) + rng.normal() * rate)
        (c0, c1), _ = nnls(np.column_stack([np.ones_like(rate), rate]), error)
        expected = 0.0 if c0 + c1 <= 0 else min(c1 / (c0 + c1), MAX_RATE_SHARE)
        assert _rate_share(error, rate) == pytest.approx(expected, abs=1e-9)
