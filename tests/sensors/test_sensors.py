"""Virtual sensor and excitations: the document's experiments, seeded, physically sensible."""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy import signal

from hystkit.metrics import loop_area, r2
from hystkit.sensors import VirtualSensor, simulate_experiment
from hystkit.signals import excitation, filtered_noise
from hystkit.signals._excitations import _fir_lowpass


@pytest.mark.parametrize("name, n", [("sine", 8000), ("decay", 8000), ("chirp", 4000),
                                     ("noise", 8000)])
def test_experiments_have_the_documents_length_and_rate(name, n):
    rec = simulate_experiment(name, seed=1)
    assert rec.n_samples == n  # 40 Hz, 200 s (100 s for the chirp)
    assert rec.dt == pytest.approx(0.025)
    assert np.max(np.abs(rec.position)) <= 3.0 + 0.01


def test_same_seed_same_recording_other_seed_other_noise():
    a, b, c = (simulate_experiment("sine", s) for s in (1, 1, 2))
    np.testing.assert_array_equal(a.sensor, b.sensor)
    assert not np.array_equal(a.sensor, c.sensor)


def test_noise_excitation_filter_is_minus_3_db_at_4_hz():
    # The noise is white before the FIR, so its spectrum is shaped by exactly this response.
    taps = _fir_lowpass(400.0, 4.0, 501)
    _, h = signal.freqz(taps, worN=[0.5, 4.0], fs=400.0)
    assert 20 * np.log10(abs(h[1])) == pytest.approx(-3.0103, abs=1e-4)  # brentq xtol 1e-6 Hz
    assert abs(h[0]) == pytest.approx(1.0, abs=1e-3)  # pass band
    t, _ = excitation("noise", fs=400.0, seed=0)
    assert np.max(np.abs(filtered_noise(t, seed=5))) == pytest.approx(3.0)


def test_play_component_is_rate_independent():
    """Without the Prony terms, the network strain is a PI operator: the same loop at any speed."""
    sensor = VirtualSensor(prony_fractions=(), prony_taus=())
    slow_t = np.arange(0, 20, 1 / 400)
    fast_t = np.arange(0, 2, 1 / 400)
    slow = sensor.network_strain(0.01 * np.sin(2 * np.pi * 0.1 * slow_t))
    fast = sensor.network_strain(0.01 * np.sin(2 * np.pi * 1.0 * fast_t))
    # sample the slow run at the same phases as the fast one
    assert_allclose(slow[::10], fast, atol=1e-15)


def test_sensor_hysteresis_is_in_the_documents_range():
    """Calibration of the defaults (not a fit): on the sine experiment the differential output
    has a loop area of about -18 % (table 5.4) and a straight line explains about 93 % of the
    position (table 5.5: 0.928)."""
    rec = simulate_experiment("sine", seed=1)
    steady = rec.time > 20
    area = loop_area(rec.position[steady], rec.sensor[steady])
    assert -25 < area < -13
    line = np.polyval(np.polyfit(rec.sensor, rec.position, 1), rec.sensor)
    assert 0.90 < r2(rec.position, line) < 0.96
