"""SINAD refuses a recording too short for its fundamental (issue 25 item 2): the tone would
sit inside the DC main lobe (bins 0-13 of the Kaiser-38 periodogram) and be discarded with DC."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.datasets import load_excerpt
from hystkit.metrics import sinad_db

FS, F0, AMP, SIGMA = 200.0, 1.0, 1.0, 0.01  # the piezo excerpt's rate and drive
DC_LOBE = 13  # bins 0-13: the Kaiser(38) window's main lobe, as sinad_db documents
# the fundamental's peak (its nearest bin) leaves the DC lobe from 13.5 periods on
NEED = math.ceil((DC_LOBE + 0.5) * FS / F0)


def _sine(n: int, seed: int = 0) -> np.ndarray:
    """An offset sine of F0 sampled at FS plus white noise of SIGMA."""
    t = np.arange(n) / FS
    return 2.0 + AMP * np.sin(2 * np.pi * F0 * t + 0.3) \
        + SIGMA * np.random.default_rng(seed).standard_normal(n)


def test_a_short_sine_is_refused_with_the_samples_it_needs():
    # 1200 samples: 6 periods, bin 6, as the piezo excerpt
    with pytest.raises(ValueError, match=rf"bin 6 of 1200 samples\) lies inside the DC main "
                                         rf"lobe.*too short.*about {NEED} samples"):
        sinad_db(_sine(1200), FS)
    # the number named is the threshold: refused just below it, a number just above
    with pytest.raises(ValueError, match="inside the DC main lobe"):
        sinad_db(_sine(NEED - 5), FS)
    assert np.isfinite(sinad_db(_sine(NEED + 5), FS))


@pytest.mark.parametrize("seed", [0, 1])
def test_the_same_sine_long_enough_has_the_closed_form_sinad(seed):
    # 2**16 samples: 328 periods, far from both lobes. The noise power is estimated from the
    # windowed record: its standard deviation is 0.053 dB at this length (tests/metrics/
    # test_metrics.py::test_sinad_white_noise), 0.3 dB ~ 5.7 sd
    x = _sine(2**16, seed)
    assert_allclose(sinad_db(x, FS), 10 * math.log10((AMP**2 / 2) / SIGMA**2), atol=0.3)


def test_the_shipped_piezo_excerpt_is_too_short_for_sinad():
    rec = load_excerpt("piezo_micromanipulator", "identification").to_recording()
    drive_hz = 1.0  # "1 Hz sine" (hystkit datasets list)
    periods = round(drive_hz * rec.n_samples / rec.fs)
    assert periods <= DC_LOBE
    for signal in (rec.position, rec.sensor):
        with pytest.raises(ValueError, match=rf"bin {periods} of {rec.n_samples} samples\) lies "
                                             rf"inside the DC main lobe.*too short"):
            sinad_db(signal, rec.fs)
