"""Tests of hystkit.metrics against hand-computed values, closed forms and invariants."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from numpy.testing import assert_allclose

from hystkit.metrics import e_max_pct, e_rms_pct, loop_area, r2, sinad_db

# Samples per period of the loop tests: a multiple of 4 (and of 360) puts the extrema of
# sin/cos and of sin(theta - phi) for whole-degree phi on the grid, so min/max
# normalisation is exact.  The chord sum then equals the exact integral times
# sin(h)/h, h = 2*pi/N, i.e. a relative error of h^2/6 = 5.1e-7.
N_PER = 3600
LOOP_RTOL = 2e-6  # ~4x the sin(h)/h discretisation error above

finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False, allow_subnormal=False)


def _theta(periods: int, n_per: int = N_PER) -> np.ndarray:
    """Phase 2*pi*t over `periods` whole periods, endpoint included (the loop closes)."""
    return 2.0 * np.pi * np.arange(periods * n_per + 1) / n_per


# --------------------------------------------------------------------------- r2


def test_r2_hand_values() -> None:
    # SS_tot = 2.25 + 0.25 + 0.25 + 2.25 = 5, SS_res = 1; only rounding error expected.
    assert_allclose(r2([1, 2, 3, 4], [1, 2, 3, 5]), 0.8, rtol=1e-14)
    # mean 0.25: SS_tot = 8.75, SS_res = 2 -> 1 - 8/35 = 27/35.
    assert_allclose(r2([-2, 0, 2, 1], [-1, 0, 1, 1]), 27 / 35, rtol=1e-14)
    # Predicting the mean gives exactly 0; the negated signal gives 1 - 4 = -3.
    y = np.array([1.0, 2.0, 3.0, 4.0])
    assert_allclose(r2(y, np.full(4, 2.5)), 0.0, atol=1e-15)  # atol: comparing with 0
    assert_allclose(r2(y - 2.5, 2.5 - y), -3.0, rtol=1e-14)


@given(arrays(float, st.integers(2, 50), elements=finite))
def test_r2_perfect_prediction_is_one(y: np.ndarray) -> None:
    assume(np.ptp(y) > 1e-3)  # keep SS_tot clear of underflow
    assert r2(y, y) == 1.0  # SS_res is exactly 0


# --------------------------------------------------------------- e_rms / e_max


def test_error_pct_hand_values() -> None:
    # scale = max|y_true| = 4, error = [0, 0, 0, -1] / 4:
    # rms = sqrt((1/16) / 4) = 1/8 -> 12.5 %, max = 1/4 -> 25 %.  Rounding only.
    t, p = [1.0, 2.0, 3.0, 4.0], [1.0, 2.0, 3.0, 5.0]
    assert_allclose(e_rms_pct(t, p), 12.5, rtol=1e-14)
    assert_allclose(e_max_pct(t, p), 25.0, rtol=1e-14)
    # Explicit scale 2 doubles both.
    assert_allclose(e_rms_pct(t, p, scale=2.0), 25.0, rtol=1e-14)
    assert_allclose(e_max_pct(t, p, scale=2.0), 50.0, rtol=1e-14)
    # scale = 2 (negative peak counts), error = [-0.5, 0, 0.5, 0]:
    # rms = sqrt(0.5 / 4) = 0.35355 -> 35.355 %, max = 50 %.
    t, p = [-2.0, 0.0, 2.0, 1.0], [-1.0, 0.0, 1.0, 1.0]
    assert_allclose(e_rms_pct(t, p), 100 * math.sqrt(0.125), rtol=1e-14)
    assert_allclose(e_max_pct(t, p), 50.0, rtol=1e-14)


@given(
    arrays(float, 20, elements=finite),
    arrays(float, 20, elements=finite),
)
def test_e_rms_not_above_e_max(t: np.ndarray, p: np.ndarray) -> None:
    assume(np.max(np.abs(t)) > 1e-3)
    rms, mx = e_rms_pct(t, p), e_max_pct(t, p)
    assert 0.0 <= rms
    # mean(d^2) <= max(d^2) holds exactly; the factor allows a few ulps of summation error.
    assert rms <= mx * (1.0 + 1e-12)


# ------------------------------------------------------------------------ sinad

N_SINAD = 2**16


def _tone(cycles: float, amp: float = 1.0, phase: float = 0.0) -> np.ndarray:
    """`cycles` periods of a sine over N_SINAD samples (`cycles` = frequency in bins)."""
    return amp * np.sin(2.0 * np.pi * cycles * np.arange(N_SINAD) / N_SINAD + phase)


@pytest.mark.parametrize("bins", [1000.0, 1000.37, 2500.5])  # on and off the bin grid
@pytest.mark.parametrize("ratio", [10.0, 100.0, 3162.0])
def test_sinad_third_harmonic(bins: float, ratio: float) -> None:
    # Only the two tones: the Kaiser(38) side lobes are below double precision, so the
    # result is 20 log10(A/a) up to rounding (observed < 1e-10 dB); 0.05 dB is generous.
    x = _tone(bins) + _tone(3 * bins, amp=1.0 / ratio, phase=0.3)
    assert_allclose(sinad_db(x), 20.0 * math.log10(ratio), atol=0.05)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sinad_white_noise(seed: int) -> None:
    rng = np.random.default_rng(seed)
    amp, sigma = 1.0, 0.01
    x = _tone(1000.37, amp=amp, phase=0.5) + sigma * rng.standard_normal(N_SINAD)
    # The noise power is estimated from the windowed record: its standard deviation is
    # (10/ln 10) * sqrt(2 sum w^4 / (sum w^2)^2) = 0.053 dB for this window and length,
    # and excluding the 38 DC/fundamental bins biases it by +0.005 dB.  0.3 dB ~ 5.7 sd.
    assert_allclose(sinad_db(x), 10.0 * math.log10((amp**2 / 2) / sigma**2), atol=0.3)


def test_sinad_pure_tone_is_very_high() -> None:
    # An off-bin tone leaves only rounding error outside its lobe: if the lobe were too
    # narrow, leaked main-lobe power would cap this far lower (170 dB with a 10-bin half-width).
    assert sinad_db(_tone(1234.4)) > 200.0


@pytest.mark.parametrize(
    ("fs", "gain", "offset"),
    [(1.0, 1.0, 0.0), (48e3, 1e-3, 0.0), (0.01, 250.0, 0.0), (1.0, 1.0, 5.0)],
)
def test_sinad_independent_of_fs_gain_and_dc(fs: float, gain: float, offset: float) -> None:
    x = _tone(800.2) + 0.05 * _tone(2400.6) + 0.02 * _tone(1777.0)
    ref = sinad_db(x)
    # Same spectrum up to scaling (and a DC lobe that is excluded): rounding only.
    assert_allclose(sinad_db(gain * x + offset, fs=fs), ref, atol=1e-9)


# -------------------------------------------------------------------- loop area


@pytest.mark.parametrize("periods", [1, 3, 10])
def test_loop_area_circle(periods: int) -> None:
    th = _theta(periods)
    # (cos, sin) runs counter-clockwise: oint y dx = -pi for the unit circle, the
    # unit-square normalisation (radius 1/2) makes it -pi/4 per cycle.
    expected = -100.0 * math.pi / 4
    assert_allclose(loop_area(np.cos(th), np.sin(th)), expected, rtol=LOOP_RTOL)
    # Reversed orientation (clockwise) flips the sign.
    assert_allclose(loop_area(np.cos(th), -np.sin(th)), -expected, rtol=LOOP_RTOL)
    assert_allclose(loop_area(np.cos(th[::-1]), np.sin(th[::-1])), -expected, rtol=LOOP_RTOL)


@pytest.mark.parametrize("periods", [1, 3, 10])
@pytest.mark.parametrize("phi_deg", [10, 30, 90, 135, -45])
def test_loop_area_ellipse_phase_lag(periods: int, phi_deg: int) -> None:
    phi = math.radians(phi_deg)
    th = _theta(periods)
    # x = sin th, y = sin(th - phi): oint y dx = int sin(th - phi) cos th dth = -pi sin phi;
    # both signals span [-1, 1], so the normalised integral is a quarter of that.
    # A lagging output (phi > 0) runs counter-clockwise and gives a negative area.
    expected = -100.0 * (math.pi / 4) * math.sin(phi)
    assert_allclose(loop_area(np.sin(th), np.sin(th - phi)), expected, rtol=LOOP_RTOL)


@pytest.mark.parametrize("n_per", [N_PER, 1001])  # symmetric and non-symmetric grids
def test_loop_area_monotone_is_zero(n_per: int) -> None:
    x = np.sin(_theta(3, n_per))
    # y = x telescopes exactly; for other monotone y the down sweep retraces the up
    # sweep's chords in reverse.  Only rounding remains: 1e-9 of the 100 % scale.
    for y in (x, np.tanh(3 * x) + x**3, 2.0 - 0.5 * x):
        assert_allclose(loop_area(x, y), 0.0, atol=1e-9 * 100)


def test_loop_area_less_than_a_cycle_counts_as_one() -> None:
    # A single up-sweep along y = x: int_0^1 x dx = 1/2, normalised as one cycle -> 50 %.
    x = np.linspace(0.0, 1.0, 11)
    assert_allclose(loop_area(x, x), 50.0, rtol=1e-14)  # trapezoid is exact for y = x


def test_loop_area_cycle_count_ignores_noise_and_flat_runs() -> None:
    rng = np.random.default_rng(7)
    th = _theta(1)[:-1]
    phi = math.radians(30)
    # One loop with a clipped (flat-topped) input and 0.2 % noise on both signals.
    x = np.clip(1.3 * np.sin(th), -1.0, 1.0) + 0.002 * rng.standard_normal(th.size)
    y = np.sin(th - phi) + 0.002 * rng.standard_normal(th.size)
    one = loop_area(np.r_[x, x[0]], np.r_[y, y[0]])
    # Repeating the loop must not change the per-cycle area: the repeated path's integral
    # is exactly k times the single one, so this only tests the cycle count (rounding only).
    for k in (3, 10):
        many = loop_area(np.r_[np.tile(x, k), x[0]], np.r_[np.tile(y, k), y[0]])
        assert_allclose(many, one, rtol=1e-9)


def test_loop_area_noisy_ellipse_close_to_clean() -> None:
    rng = np.random.default_rng(3)
    th = _theta(3)
    phi = math.radians(30)
    noise = 0.002 * rng.standard_normal((2, th.size))
    noisy = loop_area(np.sin(th) + noise[0], np.sin(th - phi) + noise[1])
    # The min/max normalisation picks up the noise extremes (~4 sd = 0.4 % of each range),
    # shrinking the area by ~1 %; 2 % tolerance.  Counting every noise wiggle as a
    # reversal would instead divide by hundreds of cycles.
    assert_allclose(noisy, -100.0 * (math.pi / 4) * math.sin(phi), rtol=0.02)


@given(st.floats(1e-3, 1e3), st.floats(-1e3, 1e3), st.floats(1e-3, 1e3), st.floats(-1e3, 1e3))
def test_loop_area_affine_invariant(a: float, b: float, c: float, d: float) -> None:
    th = _theta(2, 360)
    x, y = np.sin(th), np.sin(th - 0.7)
    # Normalisation removes positive scaling and offsets; offsets up to 1e6 times the
    # span cost ~1e-10 relative precision, so rtol = 1e-8.
    assert_allclose(loop_area(a * x + b, c * y + d), loop_area(x, y), rtol=1e-8)


# ------------------------------------------------------------------ error cases

MetricPair = Callable[..., float]
GOOD = np.array([1.0, 2.0, 3.0, 4.0])
PAIR_FUNCS = [r2, e_rms_pct, e_max_pct, loop_area]


@pytest.mark.parametrize("func", PAIR_FUNCS)
@pytest.mark.parametrize(
    ("a", "b", "match"),
    [
        (GOOD, GOOD[:3], "differ in length"),
        ([1.0], [1.0], "at least 2 samples"),
        ([1.0, np.nan, 3.0], [1.0, 2.0, 3.0], "NaN or infinite"),
        ([1.0, 2.0, 3.0], [1.0, np.inf, 3.0], "NaN or infinite"),
        (np.ones((2, 2)), np.ones((2, 2)), "must be 1-D"),
    ],
)
def test_pair_functions_reject_bad_input(
    func: MetricPair, a: object, b: object, match: str
) -> None:
    with pytest.raises(ValueError, match=match):
        func(a, b)


def test_constant_inputs_rejected() -> None:
    with pytest.raises(ValueError, match="y_true is constant"):
        r2([2.0, 2.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="must not be constant"):
        loop_area([1.0, 1.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="must not be constant"):
        loop_area([1.0, 2.0, 3.0], [0.5, 0.5, 0.5])


@pytest.mark.parametrize("func", [e_rms_pct, e_max_pct])
@pytest.mark.parametrize("scale", [0.0, -1.0, math.inf, math.nan])
def test_bad_scale_rejected(func: MetricPair, scale: float) -> None:
    with pytest.raises(ValueError, match="scale must be finite"):
        func(GOOD, GOOD, scale=scale)


@pytest.mark.parametrize("func", [e_rms_pct, e_max_pct])
def test_all_zero_reference_needs_explicit_scale(func: MetricPair) -> None:
    with pytest.raises(ValueError, match="scale must be finite"):
        func([0.0, 0.0], [1.0, 1.0])


def test_sinad_rejects_bad_input() -> None:
    with pytest.raises(ValueError, match="at least 2 samples"):
        sinad_db([1.0])
    with pytest.raises(ValueError, match="NaN or infinite"):
        sinad_db(np.r_[_tone(100.0)[:-1], np.nan])
    with pytest.raises(ValueError, match="fs must be finite"):
        sinad_db(_tone(100.0), fs=0.0)
    with pytest.raises(ValueError, match="x is constant"):
        sinad_db(np.ones(1024))
    with pytest.raises(ValueError, match="sinad_db needs at least"):
        sinad_db(np.sin(np.arange(60.0)))


@pytest.mark.parametrize("n", [4000, 4001, 64])
def test_kaiser_periodogram_is_scipys(n: int) -> None:
    from scipy.signal import periodogram

    from hystkit.metrics._metrics import kaiser_periodogram

    x = np.random.default_rng(n).standard_normal(n) + np.sin(np.arange(n) * 0.3)
    _, want = periodogram(x, fs=40.0, window=("kaiser", 38.0), detrend=False)
    assert_allclose(kaiser_periodogram(x, 40.0, 38.0), want, rtol=1e-10,
                    atol=1e-12 * want.max())


def test_loop_area_trapezoid_is_scipys() -> None:
    from scipy.integrate import trapezoid

    t = np.linspace(0, 6 * np.pi, 1000)
    x, y = np.sin(t), np.sin(t - 0.4)
    x_hat, y_hat = (x - x.min()) / np.ptp(x), (y - y.min()) / np.ptp(y)
    # three cycles: sweeps of height 1 up and down
    assert_allclose(loop_area(x, y), 100.0 / 3.0 * trapezoid(y_hat, x_hat), rtol=1e-12)
