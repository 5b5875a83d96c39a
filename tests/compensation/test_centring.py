"""Deployable centring: causal, blind to the position column, offsets handled as documented."""

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.compensation import (
    DEPLOYABLE_CENTERS,
    compensator_from_dict,
    compensator_to_dict,
    evaluate,
    fit_compensator,
)
from hystkit.compensation._centring import sensor_level
from hystkit.io import Recording
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def noise_pair():
    return simulate_experiment("noise", 1), simulate_experiment("noise", 2)


@pytest.fixture(scope="module")
def compensators(noise_pair):
    fit_rec, _ = noise_pair
    return {c: fit_compensator(fit_rec, 1, center=c, diagnose=False)
            for c in (*DEPLOYABLE_CENTERS, "recording")}


def _with(rec, **columns):
    kw = {"time": rec.time, "sensor": rec.sensor, "position": rec.position,
          "source": rec.source}
    return Recording(**{**kw, **columns})


@pytest.mark.parametrize("center", DEPLOYABLE_CENTERS)
def test_estimate_ignores_the_position_column(center, compensators, noise_pair):
    comp, rec = compensators[center], noise_pair[1]
    base = comp.estimate(rec)
    assert_array_equal(comp.estimate(_with(rec, position=rec.position + 7.0)), base)
    assert_array_equal(comp.estimate(_with(rec, position=None)), base)


@pytest.mark.parametrize("center", DEPLOYABLE_CENTERS)
def test_estimate_at_k_uses_no_future_sample(center, compensators, noise_pair):
    comp, rec = compensators[center], noise_pair[1]
    k = 3000
    future = rec.sensor.copy()
    future[k:] = future[k:] * 3.0 + 0.2
    changed = comp.estimate(_with(rec, sensor=future))
    assert_array_equal(changed[:k], comp.estimate(rec)[:k])
    assert not np.allclose(changed[k:], comp.estimate(rec)[k:])


def test_oracle_centring_does_look_ahead(compensators, noise_pair):
    """The paper's protocol is not causal: a change at the end moves the start (why it is
    labelled oracle)."""
    comp, rec = compensators["recording"], noise_pair[1]
    future = rec.sensor.copy()
    future[-100:] += 1.0
    assert not np.allclose(comp.estimate(_with(rec, sensor=future))[:100],
                           comp.estimate(rec)[:100])


@pytest.mark.parametrize("center", ["tare", "track"])
def test_tare_and_track_remove_a_constant_sensor_offset(center, compensators, noise_pair):
    comp, rec = compensators[center], noise_pair[1]
    # both levels are linear in the signal, so a constant offset passes through them exactly
    assert_allclose(comp.estimate(_with(rec, sensor=rec.sensor + 0.05)), comp.estimate(rec),
                    rtol=0, atol=1e-9)


def test_tare_level_is_the_running_mean_of_the_tare_window():
    s = np.random.default_rng(0).normal(size=200)
    level = sensor_level("tare", s, 0.1, tare_seconds=2.0, track_seconds=1.0)
    assert_allclose(level[:20], np.cumsum(s[:20]) / np.arange(1, 21))
    assert_allclose(level[20:], np.mean(s[:20]))


def test_track_level_is_pandas_adjusted_ewm():
    s = np.random.default_rng(1).normal(size=500)
    dt, tau = 0.1, 3.0
    level = sensor_level("track", s, dt, tare_seconds=1.0, track_seconds=tau)
    reference = pd.Series(s).ewm(alpha=1 - np.exp(-dt / tau), adjust=True).mean().to_numpy()
    assert_allclose(level, reference, rtol=1e-10, atol=1e-12)


def test_tare_rest_position_moves_the_estimate(compensators, noise_pair):
    comp, rec = compensators["tare"], noise_pair[1]
    shifted = comp.estimate(rec, rest_position=comp.rest_position + 1.5)
    assert_allclose(shifted - comp.estimate(rec), 1.5)


def test_a_decreasing_sensor_is_flipped_and_stored(noise_pair):
    fit_rec, val_rec = noise_pair
    up = fit_compensator(fit_rec, 1, diagnose=False)
    down = fit_compensator(_with(fit_rec, sensor=-fit_rec.sensor), 1, diagnose=False)
    assert (up.polarity, down.polarity) == (1.0, -1.0)
    assert_allclose(down.estimate(_with(val_rec, sensor=-val_rec.sensor)), up.estimate(val_rec),
                    rtol=0, atol=1e-9)
    assert compensator_from_dict(compensator_to_dict(down)).polarity == -1.0


def test_model_file_without_the_new_keys_still_loads(compensators, noise_pair):
    """A file of the first format (center: recording, no polarity / tare / ranges) runs the
    paper's protocol: own sensor mean removed."""
    comp, rec = compensators["recording"], noise_pair[1]
    old = compensator_to_dict(comp)
    for key in ("polarity", "tare_seconds", "track_seconds", "sensor_reference",
                "rest_position", "position_range"):
        del old[key]
    back = compensator_from_dict(old)
    s = (rec.sensor - rec.sensor.mean()) / comp.scaling.sensor_scale
    p, _ = comp.family.simulate(comp.structure, comp.params, s)
    expected = p * comp.scaling.position_scale + comp.scaling.position_offset
    assert_allclose(back.estimate(rec), expected, rtol=0, atol=1e-12)


def test_evaluate_reports_deployable_and_oracle_side_by_side(compensators, noise_pair):
    comp, rec = compensators["fit"], noise_pair[1]
    scores = evaluate(comp, rec)
    assert scores["center"] == "fit" and scores["center_oracle"] == "recording (oracle)"
    oracle = comp.oracle()
    mean = float(rec.position.mean())
    residual = rec.position - oracle.estimate(rec, mean)
    expected = 1 - np.sum(residual ** 2) / np.sum((rec.position - mean) ** 2)
    assert scores["r2_oracle"] == pytest.approx(expected, rel=1e-12)
    deployable = rec.position - comp.estimate(rec)
    assert scores["r2"] == pytest.approx(
        1 - np.sum(deployable ** 2) / np.sum((rec.position - mean) ** 2), rel=1e-12)
