"""The measured supply channel v0 in eq. 4.3 (sec. 4.2.1): closed forms, the virtual sensor's
bridge supply drift removed, bad input, CLI."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_allclose

from hystkit.cli import main
from hystkit.errors import InputError
from hystkit.io import RawFormat, read_raw_config
from hystkit.preprocess import (
    PreprocessSettings,
    bridge_kernel,
    bridge_resistance,
    bridge_voltage,
    downsample,
    lowpass_zero_phase,
)
from hystkit.preprocess import preprocess_raw as run
from hystkit.sensors import ScopeSettings, VirtualSensor, simulate_raw

QUIET = VirtualSensor(noise_rel=0.0)
NOMINAL = PreprocessSettings(r_bridge=10e3, v_supply=2.0)
MEASURED = PreprocessSettings(r_bridge=10e3, v_supply=2.0, supply_channel=True)
# 2 % peak-to-peak over one 2 s period: the whole drift inside a short recording.
DRIFT = {"fs": 5e4, "bridge_supply_drift": 0.01, "bridge_drift_period": 2.0}


def _ext() -> np.ndarray:
    return np.array([-np.inf, 0, np.inf, 0] * 2)


# --------------------------------------------------------------------------- closed forms


def test_eq_4_3_with_the_measured_supply_recovers_r_exactly():
    """A known supply trace through eq. 4.2 and back through eq. 4.3 (vectorised and the fused
    kernel): R to rounding; the nominal V0 instead gives the closed-form error
    R_est = (R_br + R) / s - R_br with s = V0(t) / V0."""
    rng = np.random.default_rng(4)
    n, r_bridge = 10_000, 10e3
    r = 22.4e3 * (1 + 0.05 * rng.standard_normal((2, n)))
    s = 1 + 0.01 * np.sin(np.linspace(0, 6 * np.pi, n))  # 1 % drift
    v0 = 2.0 * s
    v1, v2 = bridge_voltage(r, r_bridge, v0)
    assert_allclose(bridge_resistance(v1, r_bridge, v0), r[0], rtol=1e-12)  # rounding only
    got, bad, _ = bridge_kernel(v1, v2, r_bridge, 2.0, _ext(), v0)
    assert list(bad) == [-1, -1]
    assert_allclose(got, r, rtol=1e-12)
    nominal, _, _ = bridge_kernel(v1, v2, r_bridge, 2.0, _ext())
    assert_allclose(nominal, (r_bridge + r) / s - r_bridge, rtol=1e-12)
    assert np.max(np.abs(nominal / r - 1)) > 0.01  # the drift does show without v0


def test_kernel_with_v0_in_chunks_equals_whole():
    rng = np.random.default_rng(5)
    v = rng.uniform(0.5, 0.7, (2, 999))
    v0 = rng.uniform(1.9, 2.1, 999)
    whole = bridge_kernel(v[0], v[1], 1e4, 2.0, _ext(), v0)
    ext, parts = _ext(), []
    for part in (slice(0, 1), slice(1, 400), slice(400, 999)):
        r, _, ext = bridge_kernel(v[0, part], v[1, part], 1e4, 2.0, ext, v0[part])
        parts.append(r)
    assert np.array_equal(np.concatenate(parts, axis=1), whole[0])
    assert np.array_equal(ext, whole[2])


# --------------------------------------------------------------------------- virtual sensor


@pytest.fixture(scope="module")
def drifting(tmp_path_factory):
    """2 s of the sine at 50 kHz with a 1 % bridge supply drift, without scope noise (so only
    the drift and float32 storage stand between the file and the truth), and the same without
    drift."""
    folder = tmp_path_factory.mktemp("supply")
    quiet = {"bridge_noise_v": 0.0, "supply_channel": True}
    drift = folder / "drift.parquet"
    truth = simulate_raw(drift, "sine", 2, sensor=QUIET, scope=ScopeSettings(**DRIFT, **quiet),
                         duration=2)
    steady = folder / "steady.parquet"
    simulate_raw(steady, "sine", 2, sensor=QUIET, scope=ScopeSettings(fs=5e4, **quiet),
                 duration=2)
    return drift, steady, truth


def test_v0_removes_the_drift(drifting):
    """With v0 the drifting file gives what the steady one gives (to float32 storage of the
    voltages, ~1e-7 of R); with the nominal V0 it gives the closed-form error of the drift
    taken through the same filter chain."""
    drift, steady, truth = drifting
    measured, reference = run(drift, MEASURED), run(steady, NOMINAL)
    for key in ("dr1", "dr2"):
        assert np.max(np.abs(measured.extra[key] - reference.extra[key])) < 1e-6
    nominal = run(drift, NOMINAL)
    s = ScopeSettings(**DRIFT).bridge_supply(truth.time) / 2.0
    r_est = (10e3 + truth.resistance) / s - 10e3  # eq. 4.3 with V0 where the supply was V0 s
    r_out = downsample(lowpass_zero_phase(r_est, truth.fs_internal), truth.fs_internal, 40.0)
    expected = (r_out - r_out.mean(axis=1, keepdims=True)) / r_out.mean(axis=1, keepdims=True)
    true = truth.gauge_changes()
    for g, key in enumerate(("dr1", "dr2")):
        # the pipeline's decimation vs filtfilt at 400 Hz: well under 1e-5 of dR/R
        assert np.max(np.abs(nominal.extra[key] - expected[g])[1:-1]) < 1e-5
        error = nominal.extra[key] - true[key]
        # The drift's size: (R_br + R) / R * 1 % of the gauge's R in dR/R (1.45 % for R1).
        r_mean = truth.resistance[g].mean()
        assert 0.5 * (10e3 + r_mean) / r_mean * 0.01 < np.max(np.abs(error))
        assert np.max(np.abs(measured.extra[key] - true[key])) < 1e-4 * np.max(np.abs(error))


def test_report_names_the_measured_supply(drifting):
    drift, _, _ = drifting
    v0 = pd.read_parquet(drift, columns=["v0"])["v0"].to_numpy(dtype=float)
    rep = run(drift, MEASURED).report
    assert rep.supply == "measured"
    assert rep.v0_mean_v == pytest.approx(v0.mean(), rel=1e-12)
    assert (rep.v0_min_v, rep.v0_max_v) == (v0.min(), v0.max())
    nominal = run(drift, NOMINAL).report
    assert (nominal.supply, nominal.v0_mean_v) == ("nominal", None)


def test_default_scope_output_is_unchanged_by_the_option(tmp_path):
    """A steady supply with a v0 column: the other channels bit for bit as without it."""
    plain, with_v0 = tmp_path / "plain.parquet", tmp_path / "v0.parquet"
    simulate_raw(plain, "sine", 7, scope=ScopeSettings(fs=2e4), duration=0.5)
    simulate_raw(with_v0, "sine", 7, scope=ScopeSettings(fs=2e4, supply_channel=True),
                 duration=0.5)
    a, b = pd.read_parquet(plain), pd.read_parquet(with_v0)
    assert list(b.columns) == list(a.columns) + ["v0"]
    assert a.equals(b[a.columns])
    assert "supply_channel" not in read_raw_config(plain.with_suffix(".toml"))
    assert read_raw_config(with_v0.with_suffix(".toml"))["supply_channel"] is True
    # the v0 column is the steady 2 V plus the 0.5 mV scope noise
    assert b["v0"].mean() == pytest.approx(2.0, abs=3 * 0.5e-3 / np.sqrt(len(b)))
    assert b["v0"].std() == pytest.approx(0.5e-3, rel=0.02)


# --------------------------------------------------------------------------- bad input


@pytest.fixture(scope="module")
def frame(drifting):
    return pd.read_parquet(drifting[0]).astype(float)


def _fails(path: Path, *fragments: str, fmt: RawFormat | None = None) -> None:
    with pytest.raises(InputError, match=re.escape(str(path))) as info:
        run(path, MEASURED, fmt)
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message


@pytest.mark.parametrize("value, row, words", [
    (0.3, 4321, "is not above the bridge voltage"),  # below the ~0.6 V of v1
    (-1.0, 77, "is not positive"),
])
def test_v0_not_above_the_bridge_voltage_names_column_and_row(frame, tmp_path, value, row,
                                                              words):
    bad = frame.copy()
    bad.loc[row, "v0"] = value
    path = tmp_path / "bad.csv"
    bad.to_csv(path, index=False)
    _fails(path, "column 'v0'", f"row {row + 1} ", f"(line {row + 2})", words)


def test_bridge_voltage_above_v0_names_v0(frame, tmp_path):
    bad = frame.copy()
    bad.loc[999, "v2"] = bad.loc[999, "v0"]  # V_m = v0: eq. 4.3 gives R = 0, undefined beyond
    path = tmp_path / "eq.csv"
    bad.to_csv(path, index=False)
    _fails(path, "column 'v0'", "row 1000 ", "bridge voltage v2")


def test_missing_v0_column_is_named(frame, tmp_path):
    path = tmp_path / "nov0.parquet"
    frame.drop(columns="v0").to_parquet(path, index=False)
    _fails(path, "missing column 'v0'", "supply_channel")
    _fails(path, "missing column 'Ch D'", fmt=RawFormat(columns=(("v0", "Ch D"),)))
    run(path, NOMINAL)  # without the channel asked for, the file is fine


def test_renamed_v0_column(frame, tmp_path):
    path = tmp_path / "renamed.parquet"
    frame.rename(columns={"v0": "Ch D"}).to_parquet(path, index=False)
    got = run(path, MEASURED, RawFormat(columns=(("v0", "Ch D"),)))
    assert got.report.supply == "measured"


# --------------------------------------------------------------------------- CLI


def test_cli_supply_drift_round_trip(tmp_path, capsys):
    raw, truth = tmp_path / "run.parquet", tmp_path / "truth.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--raw", "--scope-rate", "2e4",
                 "--duration", "3", "--supply-drift", "0.01", "--supply-drift-period", "3",
                 "--supply-channel", "--out", str(raw), "--truth", str(truth)]) == 0
    assert "bridge supply drift 1 %" in capsys.readouterr().out
    with_v0, without = tmp_path / "with.csv", tmp_path / "without.csv"
    assert main(["preprocess", str(raw), "--out", str(with_v0)]) == 0  # the .toml asks for v0
    assert "measured v0 used in eq. 4.3" in capsys.readouterr().out
    assert main(["preprocess", str(raw), "--no-supply-channel", "--out", str(without)]) == 0
    assert "nominal V0 = 2 V" in capsys.readouterr().out
    exact = pd.read_csv(truth)
    err_with = np.abs(pd.read_csv(with_v0)["dr1"] - exact["dr1"]).max()
    err_without = np.abs(pd.read_csv(without)["dr1"] - exact["dr1"]).max()
    # scope noise at 20 kHz leaves ~1e-4; the drift ~1.4e-2
    assert err_with < 1e-3 and err_without > 1e-2


def test_cli_bad_v0_is_one_line_and_writes_nothing(frame, tmp_path, capsys):
    bad = frame.copy()
    bad.loc[10, "v0"] = 0.1
    path, out = tmp_path / "bad.csv", tmp_path / "out.csv"
    bad.to_csv(path, index=False)
    assert main(["preprocess", str(path), "--r-bridge", "1e4", "--v-supply", "2",
                 "--supply-channel", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("hystkit: error: ")
    assert "column 'v0'" in err and "row 11 " in err
    assert not out.exists() and not out.with_suffix(".json").exists()
    assert list(tmp_path.iterdir()) == [path]  # no temporary left behind


def test_cli_force(frame, tmp_path, capsys):
    path, out = tmp_path / "ok.parquet", tmp_path / "out.csv"
    frame.to_parquet(path, index=False)
    options = ["preprocess", str(path), "--r-bridge", "1e4", "--v-supply", "2", "--out",
               str(out)]
    assert main(options + ["--supply-channel"]) == 0
    first = out.read_bytes()
    assert main(options + ["--no-supply-channel"]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_bytes() == first  # refused: untouched
    assert main(options + ["--no-supply-channel", "--force"]) == 0
    assert out.read_bytes() != first  # the nominal V0 gives other numbers
