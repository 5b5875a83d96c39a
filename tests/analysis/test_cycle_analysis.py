"""Per-cycle analysis against closed forms and invariants (issue 14.3)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.analysis import (
    cycle_bounds,
    cycle_table,
    drift_rate,
    enclosed_area,
    input_minima,
    split_cycles,
)
from hystkit.metrics import REVERSAL_DEADBAND, confirmed_reversals, loop_area

FS = 40.0  # Hz, the recordings' rate
PERIOD = 2.0  # s, the document's sine (T = 2 s)


def _ellipse(a: float, b: float, phi: float, n_periods: int, n_per: int = 400):
    """x = a sin(w t), y = b sin(w t + phi) over whole periods (ends at a sample of x = 0)."""
    t = np.arange(n_periods * n_per + 1) / n_per * PERIOD
    w = 2 * np.pi / PERIOD
    return t, a * np.sin(w * t), b * np.sin(w * t + phi)


def _polygon_area(a: float, b: float, phi: float, n: int) -> float:
    """Area of the ellipse's inscribed n-gon: the affine image (det a b sin phi) of the regular
    n-gon in the unit circle, area n/2 sin(2 pi / n); -> pi a b sin(phi) for large n."""
    return a * b * math.sin(phi) * n / 2 * math.sin(2 * math.pi / n)


@pytest.mark.parametrize("phi", [0.3, 1.0, -0.7])
def test_ellipse_area_is_pi_a_b_sin_phi(phi):
    a, b = 3.0, 0.15
    _, x, y = _ellipse(a, b, phi, 1, n_per=4000)
    # the trapezoid rule of oint y dx is the shoelace area of the sampled polygon, exactly
    assert_allclose(enclosed_area(x, y), _polygon_area(a, b, phi, 4000), rtol=1e-12)
    assert_allclose(enclosed_area(x, y), math.pi * a * b * math.sin(phi), rtol=1e-6)


def test_per_cycle_areas_are_the_ellipse_and_its_normalised_area():
    a, b, phi = 3.0, 0.15, 0.4
    t, x, y = _ellipse(a, b, phi, 6)
    table = cycle_table(t, x, {"y": y})
    # Minima at 3/4 period: 5 complete cycles between the 6 minima of 6 periods.
    assert table.n_cycles == 5
    # each cycle is the sampled 400-gon (minima fall on samples)
    assert_allclose(table.area["y"], _polygon_area(a, b, phi, 400), rtol=1e-12)
    # eq. 5.15 normalises both ranges to 1 (2a, 2b): pi/4 sin(phi) of the unit square, in %;
    # the polygon and the sampled peak of y (off by up to b (1 - cos(pi/400))) cost ~1e-4.
    assert_allclose(table.area_pct["y"], 25 * math.pi * math.sin(phi), rtol=2e-4)
    # and is the metrics module's own number on each closed cycle
    k = 2
    lo, hi = table.start[k], table.stop[k] + 1
    assert table.area_pct["y"][k] == loop_area(x[lo:hi], y[lo:hi])


def test_linear_drift_gives_its_slope_per_hour_and_per_cycle():
    slope = 0.02 / 3600.0  # dR/R per second: 2 % per hour
    t = np.arange(0, 200, 1 / FS)
    x = -3 * np.cos(2 * np.pi * t / PERIOD)  # starts at a minimum, like a load cycle
    y = 0.1 * np.sin(2 * np.pi * t / PERIOD + 0.5) + 0.02 * x**2 + slope * t
    table = cycle_table(t, x, {"y": y})
    assert table.n_cycles == 99
    drift = table.drift["y"]
    # The periodic part has the same mean over every whole cycle, so only rounding remains.
    assert_allclose(drift.per_hour, 0.02, rtol=1e-9)
    assert_allclose(drift.per_cycle, slope * PERIOD, rtol=1e-9)
    assert_allclose(table.drift_between("y"), slope * PERIOD, rtol=1e-7)
    assert drift.stderr_per_hour < 1e-9


def test_drift_rate_standard_error_is_the_textbook_one():
    t = np.array([0.0, 3600.0, 7200.0, 10800.0])
    y = np.array([0.0, 1.0, 1.0, 3.0])
    rate = drift_rate(t, y, mean_duration=2.0)
    # closed form of simple regression on hours 0..3: slope 0.9, SE sqrt(RSS/(n-2)/Sxx)
    assert_allclose(rate.per_hour, 0.9)
    resid = y - (y.mean() + 0.9 * (np.arange(4) - 1.5))
    assert_allclose(rate.stderr_per_hour, math.sqrt(np.sum(resid**2) / 2 / 5.0))


def _ar1(rng: np.random.Generator, phi: float, n: int) -> np.ndarray:
    """Stationary AR(1) series of unit innovation variance: e_i = phi e_(i-1) + w_i."""
    e = np.empty(n)
    e[0] = rng.normal() / math.sqrt(1 - phi**2)
    for i in range(1, n):
        e[i] = phi * e[i - 1] + rng.normal()
    return e


def test_drift_standard_error_matches_the_true_spread_under_ar1_offsets():
    """Review 14, sec. 6: the i.i.d. error was ~7 times too small on autocorrelated offsets."""
    n, phi, slope = 200, 0.6, 1e-3  # cycles, lag-1 correlation, offset unit per s
    t = 2.0 * np.arange(n)  # s, one 2 s cycle each
    # Exact standard deviation of the least-squares slope: c^T Sigma c, c = (t - mean) / Sxx,
    # Sigma_ij = phi^|i-j| / (1 - phi^2) for unit innovations.
    c = (t - t.mean()) / np.sum((t - t.mean()) ** 2)
    lag = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    true_sd = 3600.0 * math.sqrt(c @ (phi**lag / (1 - phi**2)) @ c)  # per hour
    rng = np.random.default_rng(0)
    fits = [drift_rate(t, slope * t + _ar1(rng, phi, n), 2.0) for _ in range(200)]
    est = np.array([f.per_hour for f in fits])
    se = np.array([f.stderr_per_hour for f in fits])
    iid = se * np.sqrt([(1 - f.residual_lag1) / (1 + f.residual_lag1) for f in fits])
    # 200 draws estimate a standard deviation to about +-5 % (1 sigma): 15 % is 3 sigma.
    assert abs(est.std() / true_sd - 1) < 0.15
    assert abs(math.sqrt(np.mean(se**2)) / true_sd - 1) < 0.15
    assert np.mean(iid) < 0.6 * true_sd  # what the i.i.d. error said: about half (phi 0.6)
    coverage = np.mean(np.abs(est - 3600.0 * slope) < 2 * se)
    assert 0.88 < coverage < 0.99  # 0.954 for a calibrated error; binomial sd 0.015
    assert_allclose(np.mean([f.n_effective for f in fits]), n * 0.4 / 1.6, rtol=0.15)
    # a straight line is rarely called not linear (3-sigma rule; a few % from optimistic halves)
    assert np.mean([not f.linear for f in fits]) < 0.06


def test_a_decaying_drift_is_flagged_as_not_linear():
    # creep-like offsets: fast early, slow late (the review's sine: 38 then 6 %/h)
    t = 2.0 * np.arange(100)
    y = 0.02 * (1 - np.exp(-t / 60.0)) + 1e-4 * _ar1(np.random.default_rng(1), 0.5, 100)
    drift = drift_rate(t, y, 2.0)
    first, first_se, second, second_se = drift.half_slopes_per_hour
    assert drift.linear is False and first > second + 3 * math.hypot(first_se, second_se)
    # halves of a straight line agree with the whole
    line = drift_rate(t, 1e-3 * t, 2.0)
    assert line.linear is True
    assert_allclose(line.half_slopes_per_hour[::2], [3.6, 3.6], rtol=1e-9)


def test_split_by_cycles_then_concatenated_is_the_whole():
    rng = np.random.default_rng(3)
    t = np.arange(0, 60, 1 / FS)
    x = 2 * np.exp(-t / 40) * np.sin(np.pi * t) + 0.005 * rng.standard_normal(t.size)
    y = rng.standard_normal(t.size)
    bounds = cycle_bounds(x)
    pieces = split_cycles(bounds, t, x, y)
    for i, whole in enumerate((t, x, y)):
        assert np.array_equal(np.concatenate([p[i] for p in pieces]), whole)
    # and the cycles' closed-loop areas add up to the line integral over all of them
    table = cycle_table(t, x, {"y": y})
    lo, hi = table.start[0], table.stop[-1] + 1
    assert_allclose(table.area["y"].sum(), enclosed_area(x[lo:hi], y[lo:hi]), rtol=1e-12)


def test_minima_of_a_noisy_decaying_sine_are_its_true_minima():
    rng = np.random.default_rng(0)
    t = np.arange(0, 40, 1 / FS)
    x = 2 * np.exp(-t / 30) * np.sin(np.pi * t - np.pi / 2)  # minima at t = 0, 2, 4, ...
    noisy = x + 0.01 * rng.standard_normal(t.size)
    minima = input_minima(noisy)
    assert minima.size == 20
    # within a few samples of the true minima despite noise (flat bottoms)
    assert np.max(np.abs(t[minima] - 2 * np.arange(20))) < 0.2


def test_a_sine_started_mid_range_has_no_cycle_before_its_first_minimum():
    t = np.arange(0, 10, 1 / FS)
    minima = input_minima(np.sin(np.pi * t))
    assert_allclose(t[minima], [1.5, 3.5, 5.5, 7.5, 9.5])


@pytest.mark.parametrize(("x", "match"), [
    (np.zeros(10), "constant"),
    (np.array([0.0, np.nan, 1.0]), "NaN"),
    (np.sin(np.linspace(0, 3, 50)), "no complete cycle"),
])
def test_bad_inputs_are_refused_with_a_reason(x, match):
    with pytest.raises(ValueError, match=match):
        cycle_table(np.arange(x.size) / FS, x, {"y": np.arange(x.size, dtype=float)})


def test_one_comparator_gives_the_cycles_and_the_loop_area_count():
    """A quantised, noisy triangle wave: the shared comparator confirms its true turning points,
    alternating, and those minima are the cycle cuts (review 14, sec. 9)."""
    period, n_periods = 200, 6
    k = np.arange(period * n_periods + 1)
    phase = (k % period) / period
    x = np.where(phase < 0.5, 2 * phase, 2 - 2 * phase)  # minima at k = 0, 200, ..., maxima 100..
    noisy = np.round(x + 0.002 * np.random.default_rng(5).standard_normal(k.size), 3)
    rev = confirmed_reversals(noisy, REVERSAL_DEADBAND * np.ptp(noisy))
    true = np.arange(period // 2, k[-1], period // 2)  # the last extremum (the end) is open
    assert np.all(np.abs(rev.index - true) <= 3)  # noise of 0.002 moves a turn by a few samples
    assert_allclose(rev.is_max, np.arange(true.size) % 2 == 0)
    assert rev.rising_first
    minima = input_minima(noisy)
    assert_allclose(minima[1:], rev.index[~rev.is_max])
    assert minima[0] <= 3  # the record starts at its lowest point: a cycle from the start
