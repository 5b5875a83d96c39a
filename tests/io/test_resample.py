"""``--resample HZ``: jittered time onto a uniform grid, checked against closed forms."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.cli import main
from hystkit.errors import InputError
from hystkit.io import ReadOptions, read_recording
from hystkit.io._resample import MAX_GAP_STEPS

F0 = 1.0  # Hz
OMEGA = 2 * np.pi * F0


def _csv(path, time, position, sensor):
    pd.DataFrame({"time": time, "position": position, "sensor": sensor}).to_csv(path,
                                                                                 index=False)
    return path


def _jittered(n: int, step: float, jitter: float, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.arange(n) * step + rng.uniform(-jitter, jitter, n)


def test_jittered_sine_within_the_linear_interpolation_bound(tmp_path):
    # 100 Hz nominal with +-2 ms jitter (the case), 10 s of a 1 Hz sine.
    t = _jittered(1000, 0.01, 0.002)
    path = _csv(tmp_path / "j.csv", t, np.sin(OMEGA * t), np.cos(OMEGA * t))
    with pytest.raises(InputError, match="non-uniform sampling.*--resample HZ"):
        read_recording(path)
    rec = read_recording(path, options=ReadOptions(resample_hz=100.0))
    assert_allclose(np.diff(rec.time), 0.01, rtol=1e-9)  # uniform at 100 Hz
    assert rec.time[0] == t[0] and rec.time[-1] <= t[-1]
    # |f - interp f| <= h^2 / 8 * max|f''| on each bracketing step h; f'' = -omega^2 f
    right = np.searchsorted(t, rec.time).clip(1, t.size - 1)
    h = t[right] - t[right - 1]
    bound = h**2 / 8 * OMEGA**2 + 1e-12
    for values, exact in ((rec.position, np.sin(OMEGA * rec.time)),
                          (rec.sensor, np.cos(OMEGA * rec.time))):
        error = np.abs(values - exact)
        assert np.all(error <= bound)
        assert error.max() > 1e-6  # really interpolated, not the samples themselves


def test_uniform_recording_is_unchanged_at_its_own_rate(tmp_path):
    n = 500
    t = np.arange(n) / 200.0  # exactly the grid t0 + k / HZ
    rng = np.random.default_rng(1)
    x, y = rng.standard_normal(n), rng.standard_normal(n)
    path = _csv(tmp_path / "u.csv", t, x, y)
    rec = read_recording(path, options=ReadOptions(resample_hz=200.0))
    assert_array_equal(rec.time, t)
    assert_array_equal(rec.position, x)
    assert_array_equal(rec.sensor, y)


def test_upsampling_interpolates_between_samples(tmp_path):
    # a straight line is reproduced exactly by linear interpolation (to rounding)
    t = _jittered(300, 0.01, 0.002, seed=2)
    path = _csv(tmp_path / "line.csv", t, 3 * t - 1, -0.5 * t)
    rec = read_recording(path, options=ReadOptions(resample_hz=250.0))
    assert_allclose(rec.position, 3 * rec.time - 1, rtol=0, atol=1e-12)
    assert_allclose(rec.sensor, -0.5 * rec.time, rtol=0, atol=1e-12)


def test_decimation_removes_content_above_the_new_nyquist(tmp_path):
    # 1 kHz: a 1 Hz sine plus 300 Hz; at 100 Hz the 300 Hz would alias to 0 Hz (a pure
    # offset). After the anti-alias low-pass only the 1 Hz sine is left.
    t = np.arange(5000) / 1000.0
    slow, fast = np.sin(OMEGA * t), 0.5 * np.cos(2 * np.pi * 300 * t)
    path = _csv(tmp_path / "d.csv", t, slow + fast, slow)
    rec = read_recording(path, options=ReadOptions(resample_hz=100.0))
    assert_allclose(np.diff(rec.time), 0.01, rtol=1e-9)
    inner = slice(50, -50)  # 0.5 s from each end: the forwards-backwards filter's edges
    # order-8 Butterworth at 40 Hz, twice: 300 Hz attenuated by (40/300)^16 ~ 1e-14, 1 Hz
    # passed with gain 1 - 1e-26 and no phase shift
    assert_allclose(rec.position[inner], np.sin(OMEGA * rec.time[inner]), atol=1e-6)
    naive = np.interp(rec.time, t, slow + fast)  # without the filter: the alias is there
    assert np.abs(naive - np.sin(OMEGA * rec.time)).max() > 0.4


def test_gap_is_refused_with_its_row(tmp_path):
    t = np.arange(400) / 100.0
    t[200:] += 0.05  # 6 median steps missing after row 200
    path = _csv(tmp_path / "gap.csv", t, np.sin(t), np.cos(t))
    with pytest.raises(InputError, match=rf"column 'time', row 201 \(line 202\): gap of "
                                         rf"0\.06 s .*{MAX_GAP_STEPS:g} median steps"):
        read_recording(path, options=ReadOptions(resample_hz=100.0))


def test_cli_resample_option(tmp_path, capsys):
    t = _jittered(2000, 0.01, 0.002, seed=3)
    path = _csv(tmp_path / "j.csv", t, np.sin(OMEGA * t) * 0.2,
                0.01 * np.sin(OMEGA * t - 0.3))
    out = tmp_path / "m.json"
    assert main(["fit", str(path), "--cells", "1", "--out", str(out)]) == 2
    assert "--resample HZ" in capsys.readouterr().err
    assert main(["fit", str(path), "--cells", "1", "--resample", "100", "--out", str(out)]) == 0
    for bad in ("0", "-5", "inf", "nan"):
        assert main(["fit", str(path), "--resample", bad, "--out", str(out)]) == 2
        assert "--resample" in capsys.readouterr().err
