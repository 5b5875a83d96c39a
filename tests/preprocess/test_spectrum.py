"""Spectrum for choosing the cut-off (fig. 4.10): Welch PSD against closed forms, the noise
floor, the cut-off rule on lines of known height, the Butterworth overlay, CLI."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.cli import main
from hystkit.preprocess import (
    CutoffRule,
    butterworth_response,
    noise_floor,
    spectrum,
    welch_psd,
)
from hystkit.sensors import ScopeSettings, simulate_raw

FS = 1000.0
SIGMA = 1e-3  # white noise std: one-sided density 2 sigma^2 / fs = 2e-9 /Hz
DENSITY = 2 * SIGMA ** 2 / FS
SEGMENT = 10.0  # s: bins 0.1 Hz apart


def _noise(seconds: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(round(seconds * FS)) / FS
    return t, SIGMA * np.random.default_rng(seed).standard_normal(t.size)


def _line(t: np.ndarray, f: float, ratio: float) -> np.ndarray:
    """A sine whose Welch peak (bin-centred, Hann: (A^2/2) T / 1.5) is `ratio` x DENSITY."""
    amplitude = np.sqrt(2 * 1.5 * ratio * DENSITY / SEGMENT)
    return amplitude * np.sin(2 * np.pi * f * t)


def test_welch_peak_and_noise_floor_of_sine_plus_white_noise():
    t, x = _noise(200.0)
    x = x + 0.05 * np.sin(2 * np.pi * 7.3 * t)
    freq, psd, k = welch_psd(x, FS, SEGMENT)
    assert k == 39  # 200 s in 10 s segments, 50 % overlap
    assert freq[np.argmax(psd)] == pytest.approx(7.3, abs=1e-9)
    # Parseval: the line's power A^2 / 2 sits within a few bins of it
    near = np.abs(freq - 7.3) < 0.5
    assert np.trapezoid(psd[near], freq[near]) == pytest.approx(0.05 ** 2 / 2, rel=0.01)
    floor = noise_floor(psd, freq[1] - freq[0], 4.0, k)
    band = (freq > 20) & (freq < 450)
    # 4300 bins of nu = 74 chi-square: the band's mean floor is within ~1 % of the density;
    # each point is a 41-bin median, ~3 % std
    assert floor[band].mean() == pytest.approx(DENSITY, rel=0.02)
    assert np.max(np.abs(floor[band] / DENSITY - 1)) < 0.15
    # the line does not lift the floor around it (it covers 4 of 41 bins)
    assert floor[np.argmin(np.abs(freq - 7.3))] == pytest.approx(DENSITY, rel=0.15)


def test_rule_finds_the_highest_line_above_the_margin():
    """Odd harmonics of 1 Hz at 60, 40, 20 dB over the floor, then one at 3 dB: f_signal is the
    last line above 10 dB (5 Hz), the cut-off 2.5 x that."""
    t, x = _noise(200.0, seed=1)
    for f, db in ((1, 60), (3, 40), (5, 20), (7, 3)):
        x = x + _line(t, f, 10 ** (db / 10))
    result = spectrum({"differential": x}, FS, segment_s=SEGMENT, compare_cutoff=20.0)
    assert result.f_signal == pytest.approx(5.0, abs=1e-9)
    assert result.cutoff == pytest.approx(12.5)
    # the line's measured height over the floor is the one built in (Hann scalloping: none,
    # the lines are bin-centred)
    i = np.argmin(np.abs(result.freq - 5.0))
    assert 10 * np.log10(result.psd["differential"][i] / result.floor[i]) == pytest.approx(
        20, abs=1.0)
    strict = spectrum({"differential": x}, FS, segment_s=SEGMENT,
                      rule=CutoffRule(margin_db=30, safety=2.0))
    assert (strict.f_signal, strict.cutoff) == pytest.approx((3.0, 6.0))
    s = result.summary["filters"]["suggested"]
    # zero-phase 2nd order at f_c = 2.5 f: |H|^2 = 1 / (1 + q^4), q = 1 / 2.5 prewarped
    q = np.tan(np.pi * 5.0 / FS) / np.tan(np.pi * 12.5 / FS)
    assert s["gain_at_f_signal_db"] == pytest.approx(-20 * np.log10(1 + q ** 4), rel=1e-9)


def test_pure_noise_has_no_line_but_its_spectrum():
    """Issue 25.4: no line to pick a cut-off from is said, not refused; the PSD and the floor
    are there, f_signal and the cut-off are NaN, no filter is summarised."""
    _, x = _noise(60.0, seed=2)
    result = spectrum({"differential": x}, FS, segment_s=SEGMENT, compare_cutoff=20.0)
    assert result.summary["no_line"].startswith(
        "no spectral line stands 10 dB above the noise floor between 0.2 and 400 Hz, so there "
        "is no line to pick a cut-off from")
    assert np.isnan(result.f_signal) and np.isnan(result.cutoff)
    assert result.summary["f_signal_hz"] is None and result.summary["filters"] == {}
    assert list(result.response) == ["20 Hz (compare)"]  # the overlay asked for stays
    _, psd, _ = welch_psd(x, FS, SEGMENT)
    assert_allclose(result.psd["differential"], psd, rtol=1e-12)
    assert result.plot().axes  # the figure draws without an f_signal
    with pytest.raises(ValueError, match="2 Welch segment"):  # 40 s segments in 60 s
        spectrum({"differential": x}, FS, segment_s=40.0)
    assert spectrum({"differential": x + _line(np.arange(x.size) / FS, 3.0, 1e4)},
                    FS).summary["n_segments"] == 5  # default: 20 s segments, 50 % overlap


def test_no_line_in_a_short_record_names_its_resolution_and_length():
    """Review 14, sec. 7: 5 s at 40 Hz gives 2.5 s segments, bins 0.4 Hz apart, so the 4 Hz
    running median spans 10 bins and the search starts at 0.8 Hz."""
    x = np.random.default_rng(3).normal(size=200)
    assert re.search(r"the record is short \(5 s, frequency resolution 0\.4 Hz\): a "
                     r"fundamental below 0\.8 Hz .* spans only 10 bins",
                     spectrum({"differential": x}, 40.0).summary["no_line"])
    _, long = _noise(60.0, seed=2)  # 0.1 Hz bins: 40 in the median, no word on the length
    assert spectrum({"differential": long}, FS, segment_s=SEGMENT).summary["no_line"].endswith(
        "between 0.2 and 400 Hz, so there is no line to pick a cut-off from: the signal is a "
        "band, not lines (a broadband excitation), pure noise or flat")


def test_a_comparison_at_nyquist_is_skipped_with_a_reason():
    t = np.arange(4000) / 40.0  # 100 s at 40 Hz: the document's recordings
    x = _line(t, 0.5, 1e4) + 1e-3 * np.random.default_rng(4).normal(size=t.size)
    result = spectrum({"differential": x}, 40.0)
    assert list(result.summary["filters"]) == ["suggested"]
    assert result.summary["compare_skipped"] == ("20 Hz comparison skipped: at or above fs/2 = "
                                                 "20 Hz")
    kept = spectrum({"differential": x}, 40.0, compare_cutoff=10.0)
    assert kept.summary["compare_skipped"] is None and "compare" in kept.summary["filters"]


@pytest.mark.parametrize("cutoff, order", [(20.0, 2), (8.0, 2), (100.0, 4), (3.0, 1)])
def test_butterworth_overlay_is_the_zero_phase_response(cutoff, order):
    freq = np.linspace(0, FS / 2, 2001)
    h2 = butterworth_response(freq, FS, cutoff, order)
    # the bilinear Butterworth in closed form: |H|^2 = 1 / (1 + (tan(pi f/fs)/tan(pi fc/fs))^2n)
    ratio = np.tan(np.pi * freq[:-1] / FS) / np.tan(np.pi * cutoff / FS)
    assert_allclose(h2[:-1], 1 / (1 + ratio ** (2 * order)), rtol=1e-9, atol=1e-15)
    assert butterworth_response(np.array([cutoff]), FS, cutoff, order)[0] == pytest.approx(0.5)


@pytest.mark.parametrize("cutoff", [0.0, -5.0, FS / 2, 2 * FS])
def test_the_filter_and_its_overlay_refuse_the_same_cut_offs(cutoff):
    """One design (eq. 4.1) behind both: the same refusal, in the same words."""
    from hystkit.preprocess import lowpass_zero_phase

    with pytest.raises(ValueError, match="must lie between 0 and fs/2 = 500 Hz") as filtering:
        lowpass_zero_phase(np.zeros(64), FS, cutoff, 2)
    with pytest.raises(ValueError) as overlay:
        butterworth_response(np.array([1.0]), FS, cutoff, 2)
    assert str(filtering.value) == str(overlay.value)


def test_zero_phase_filter_shapes_white_noise_as_the_overlay_says():
    """PSD after lowpass_zero_phase / PSD before = |H|^4 (the power response of forward-
    backward filtering), checked where the noise is well above rounding."""
    from hystkit.preprocess import lowpass_zero_phase

    _, x = _noise(400.0, seed=3)
    y = lowpass_zero_phase(x, FS, 20.0, 2)
    freq, p_x, _ = welch_psd(x, FS, SEGMENT)
    _, p_y, _ = welch_psd(y, FS, SEGMENT)
    band = (freq > 1) & (freq < 40)
    expected = butterworth_response(freq, FS, 20.0, 2) ** 2
    # ratio of two correlated estimates: within ~5 % per bin, 1 % over the band
    assert np.mean(p_y[band] / p_x[band] / expected[band]) == pytest.approx(1, abs=0.01)


# --------------------------------------------------------------------------- CLI


@pytest.fixture(scope="module")
def raw_sine(tmp_path_factory):
    path = tmp_path_factory.mktemp("spectrum") / "sine.parquet"
    simulate_raw(path, "sine", 1, scope=ScopeSettings(fs=2e4), duration=40)
    return path


def test_cli_raw_spectrum_json_and_figure(raw_sine, tmp_path, capsys):
    out = tmp_path / "spec"
    assert main(["spectrum", str(raw_sine), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "suggested cut-off" in text and "f_c = 20 Hz" in text
    report = json.loads((out / "spectrum.json").read_text())
    assert (out / "spectrum.png").stat().st_size > 10_000
    assert report["kind"] == "raw" and report["fs_hz"] == pytest.approx(1000.0)
    assert "exceeds 10 dB over the local noise floor" in report["rule"]["text"]
    freq = np.array(report["freq_hz"])
    diff = np.array(report["psd_per_hz"]["differential"])
    floor = np.array(report["noise_floor_per_hz"])
    f_signal = report["f_signal_hz"]
    # the rule, re-checked on the written arrays
    i = np.flatnonzero(freq == f_signal)[0]
    assert diff[i] > 10 * floor[i] and diff[i] >= diff[i - 1] and diff[i] >= diff[i + 1]
    # beyond the line's main lobe (Hann: 2 bins either side) nothing clears the margin
    beyond = (freq > f_signal + 2.5 * (freq[1] - freq[0])) & (freq <= 400)
    assert np.all(diff[beyond] <= 10 * floor[beyond])
    assert report["suggested_cutoff_hz"] == pytest.approx(2.5 * f_signal)
    # the 0.5 Hz sine is the strongest line; its odd harmonics lie at 1.5, 2.5, ... Hz
    assert freq[np.argmax(diff)] == pytest.approx(0.5)
    assert 1.5 <= f_signal <= 20
    response = report["filter_amplitude_response"]
    key = next(k for k in response if "suggested" in k)
    assert_allclose(response[key], butterworth_response(freq, report["fs_hz"],
                                                        report["suggested_cutoff_hz"]))
    assert set(report["psd_per_hz"]) == {"dr1", "dr2", "differential"}


def test_cli_force_and_nothing_partial(raw_sine, tmp_path, capsys):
    out = tmp_path / "spec"
    assert main(["spectrum", str(raw_sine), "--out", str(out), "--segment", "10"]) == 0
    first = (out / "spectrum.json").read_bytes()
    assert main(["spectrum", str(raw_sine), "--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert (out / "spectrum.json").read_bytes() == first
    assert main(["spectrum", str(raw_sine), "--out", str(out), "--force"]) == 0
    assert (out / "spectrum.json").read_bytes() != first  # 20 s segments now
    # a failing run (too few Welch segments) leaves nothing behind
    empty = tmp_path / "none"
    assert main(["spectrum", str(raw_sine), "--out", str(empty), "--segment", "30"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "1 Welch segment(s) of 30 s" in err
    assert str(raw_sine) in err
    assert not empty.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["spec"]


def test_cli_on_a_preprocessed_recording(raw_sine, tmp_path, capsys):
    data = tmp_path / "sine.csv"
    assert main(["preprocess", str(raw_sine), "--out", str(data)]) == 0
    out = tmp_path / "spec"
    assert main(["spectrum", str(data), "--out", str(out), "--segment", "10"]) == 0
    report = json.loads((out / "spectrum.json").read_text())
    assert report["kind"] == "recording" and report["fs_hz"] == pytest.approx(40.0)
    assert set(report["psd_per_hz"]) == {"dr1", "dr2", "differential"}


def test_cli_bad_raw_input_is_one_line(raw_sine, tmp_path, capsys):
    import pandas as pd

    frame = pd.read_parquet(raw_sine)
    path = tmp_path / "nov0.parquet"
    frame.to_parquet(path, index=False)
    assert main(["spectrum", str(path), "--r-bridge", "1e4", "--v-supply", "2",
                 "--supply-channel", "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "missing column 'v0'" in err and str(path) in err
