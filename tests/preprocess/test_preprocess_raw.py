"""Raw scope recordings -> 40 Hz recordings: round trips on the virtual sensor, bad input, CLI.

Round trips use a noise-free gauge (``noise_rel = 0``) so that the truth itself is smooth; the
raw file still carries the scope noise, encoder noise, drift and finite edges. "Within the
noise" then means: well under the default sensor's own dR/R noise at 40 Hz, about 4e-4 std.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.csv as pa_csv
import pytest
from numpy.testing import assert_allclose
from scipy.io import savemat

from hystkit.cli import main
from hystkit.errors import InputError
from hystkit.io import RawFormat, open_raw, read_raw_config, read_recording
from hystkit.preprocess import (
    PreprocessSettings,
    RawDataWarning,
    decode,
    preprocess_raw,
)
from hystkit.sensors import ScopeSettings, VirtualSensor, simulate_raw

COUNT_MM = 0.005  # one encoder count
SENSOR_NOISE = 4e-4  # std of the default virtual sensor's dR1/R1 - dR2/R2 noise at 40 Hz
QUIET = VirtualSensor(noise_rel=0.0)
BRIDGE = PreprocessSettings(r_bridge=10e3, v_supply=2.0)


def _settings(**changes) -> PreprocessSettings:
    return PreprocessSettings(**{**vars(BRIDGE), **changes})


def _check_round_trip(result, truth) -> None:
    """40 Hz position within one count of the truth, dR/R well within the sensor noise (the
    first and last sample, half of whose filter window is extrapolated, within the noise)."""
    ref = truth.recording()
    rec = result.recording
    assert rec.n_samples == ref.n_samples
    assert_allclose(rec.time, ref.time, atol=1e-9)
    # quantisation to counts (up to half a count where the actuator turns) plus filter edges
    assert np.max(np.abs(rec.position - ref.position)) < COUNT_MM
    # The scope noise (0.5 mV, 1.2e-3 of R per sample) leaves 1e-5 (1 MHz) to 3e-5 (100 kHz) std.
    error = np.abs(rec.sensor - ref.sensor)
    assert np.max(error[1:-1]) < SENSOR_NOISE / 2
    assert np.max(error) < SENSOR_NOISE
    r_means = truth.resistance.mean(axis=1)
    assert result.report.symmetry == pytest.approx(
        2 * (r_means[0] - r_means[1]) / r_means.sum(), abs=2e-3)


@pytest.fixture(scope="module")
def sine_1mhz(tmp_path_factory):
    """4 s of the sine experiment at 1 MHz (Parquet): 4 000 001 samples per channel."""
    path = tmp_path_factory.mktemp("raw") / "sine.parquet"
    truth = simulate_raw(path, "sine", 1, sensor=QUIET, scope=ScopeSettings(fs=1e6), duration=4)
    return path, truth


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """2 s at 100 kHz, as a DataFrame to break in the bad-input tests, and its truth."""
    path = tmp_path_factory.mktemp("small") / "small.parquet"
    truth = simulate_raw(path, "sine", 3, sensor=QUIET, scope=ScopeSettings(fs=1e5), duration=2)
    return pd.read_parquet(path).astype(float), truth


def _write(frame: pd.DataFrame, path: Path) -> Path:
    if path.suffix == ".csv":
        pa_csv.write_csv(pa.Table.from_pandas(frame, preserve_index=False), path,
                         pa_csv.WriteOptions(quoting_header="none"))
    else:
        frame.to_parquet(path, index=False)
    return path


# --------------------------------------------------------------------------- round trips


def test_round_trip_at_1_mhz(sine_1mhz):
    path, truth = sine_1mhz
    result = preprocess_raw(path, BRIDGE)
    _check_round_trip(result, truth)
    rep = result.report
    assert (rep.n_samples, rep.fs_mid, rep.n_illegal, rep.n_rejected) == (4_000_001, 400, 0, 0)
    assert rep.n_edges == np.count_nonzero(np.diff(truth.counts()))
    # At the scope rate: every sample within one count, almost all exact (the rest mid-edge).
    x = np.concatenate([c.encoder for c in open_raw(path).chunks(columns=("encoder",))])
    counts, _ = decode(x, rep.encoder_levels)
    error = counts - truth.counts()
    assert np.max(np.abs(error)) <= 1
    assert np.mean(error == 0) > 0.9999


def _outputs(result) -> np.ndarray:
    rec = result.recording
    return np.vstack([rec.time, rec.position, rec.sensor, *result.extra.values()])


def _same_report(a, b) -> None:
    a, b = a.report.to_dict(), b.report.to_dict()
    for key in a:
        if key != "seconds":
            assert a[key] == b[key], key


def test_chunked_equals_whole(sine_1mhz):
    """Split run == whole run, bit for bit: 41 chunks with odd borders against one."""
    path, _ = sine_1mhz
    whole = preprocess_raw(path, _settings(chunk_size=1 << 23))  # one chunk
    chunked = preprocess_raw(path, _settings(chunk_size=99_991))  # 41 chunks, odd borders
    assert np.array_equal(_outputs(chunked), _outputs(whole))
    _same_report(chunked, whole)


def test_any_chunk_size_gives_identical_arrays(tmp_path):
    """Chunks of 1, 2, 3, 10, 997 samples and the default: the same arrays and report, bit for
    bit (the level survey, the rate and the FIR sums do not see the chunk borders)."""
    path = tmp_path / "small.csv"
    simulate_raw(path, "sine", 3, sensor=QUIET, scope=ScopeSettings(fs=10_000), duration=0.1)
    default = preprocess_raw(path, _settings())
    assert default.recording.n_samples >= 4
    for size in (1, 2, 3, 10, 997):
        result = preprocess_raw(path, _settings(chunk_size=size))
        assert np.array_equal(_outputs(result), _outputs(default)), size
        _same_report(result, default)


def test_round_trip_at_6_25_mhz_in_chunks(tmp_path):
    """The Handyscope rate of sec. 4.3.2, 1 s, processed in 24 chunks of 2**18 samples."""
    path = tmp_path / "fast.parquet"
    truth = simulate_raw(path, "chirp", 2, sensor=QUIET, scope=ScopeSettings(fs=6.25e6),
                         duration=1)
    result = preprocess_raw(path, _settings(chunk_size=1 << 18))
    _check_round_trip(result, truth)
    assert result.report.n_illegal == 0
    assert result.report.encoder_dwell_samples == 25  # 4 us at 6.25 MHz: edges span samples
    assert result.report.decimation[0][0] * result.report.decimation[1][0] == 15625


def test_csv_mat_and_parquet_agree(small, tmp_path):
    frame, truth = small
    results = [preprocess_raw(_write(frame, tmp_path / f"r{s}"), BRIDGE)
               for s in (".csv", ".parquet")]
    savemat(tmp_path / "r.mat", {c: frame[c].to_numpy() for c in frame.columns})
    results.append(preprocess_raw(tmp_path / "r.mat", BRIDGE))
    for other in results[1:]:
        assert_allclose(other.recording.position, results[0].recording.position, atol=1e-12)
        assert_allclose(other.recording.sensor, results[0].recording.sensor, atol=1e-12)
    _check_round_trip(results[0], truth)


def test_separate_logic_channels(tmp_path):
    path = tmp_path / "ab.csv"
    truth = simulate_raw(path, "noise", 4, sensor=QUIET,
                         scope=ScopeSettings(fs=2e5, encoder_mode="ab"), duration=3)
    result = preprocess_raw(path, BRIDGE)
    assert result.report.encoder_kind == "ab" and result.report.n_illegal == 0
    _check_round_trip(result, truth)


def test_injected_glitches_are_counted_and_reported(tmp_path):
    path = tmp_path / "glitchy.parquet"
    truth = simulate_raw(path, "sine", 5, sensor=QUIET,
                         scope=ScopeSettings(fs=1e6, n_missed_states=5, n_spikes=7), duration=3)
    with pytest.warns(RawDataWarning, match=r"encoder: 5 illegal double transition\(s\)"):
        result = preprocess_raw(path, BRIDGE)
    assert (result.report.n_illegal, result.report.n_rejected) == (5, 7)
    # 'continue' adds the missed state's count: the position stays within one count ...
    _check_round_trip(result, truth)
    # ... while 'hold' loses 2 counts at each glitch
    with pytest.warns(RawDataWarning, match="added nothing"):
        held = preprocess_raw(path, _settings(illegal="hold"))
    error = (held.recording.position - truth.recording().position) / COUNT_MM
    assert np.max(np.abs(error)) > 1.5


def test_level_order_is_a_setting(small, tmp_path):
    frame = small[0]
    path = _write(frame, tmp_path / "order.parquet")
    right = preprocess_raw(path, BRIDGE)
    # A and B swapped (B through the 1 kOhm resistor): all steps legal, direction reversed
    swapped = preprocess_raw(path, _settings(encoder_states=(0b00, 0b10, 0b01, 0b11)))
    assert_allclose(swapped.recording.position, -right.recording.position, atol=1e-9)
    # the top two levels swapped: half the steps change A and B at once
    _fails(path, "illegal double transitions", "--encoder-states",
           settings=_settings(encoder_states=(0b00, 0b01, 0b11, 0b10)))


def test_settings_file_round_trip(sine_1mhz):
    path, _ = sine_1mhz
    config = read_raw_config(path.with_suffix(".toml"))
    assert (config["r_bridge"], config["v_supply"], config["fs"]) == (10e3, 2.0, 1e6)
    assert config["n_samples"] == 4_000_001 and config["simulation"]["excitation"] == "sine"


# --------------------------------------------------------------------------- bad input


def _fails(path: Path, *fragments: str, settings: PreprocessSettings = BRIDGE,
           fmt: RawFormat | None = None) -> str:
    with pytest.raises(InputError, match=re.escape(str(path))) as info:
        preprocess_raw(path, settings, fmt)
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message
    return message


def test_flat_encoder_is_an_error(small, tmp_path):
    frame = small[0].copy()
    frame["encoder"] = 1.7 + 0.01 * np.random.default_rng(0).standard_normal(len(frame))
    _fails(_write(frame, tmp_path / "flat.parquet"), "'encoder'", "flat", "one level")


def test_flat_encoder_with_given_levels_is_a_warning(small, tmp_path):
    frame = small[0].copy()
    frame["encoder"] = 1.7 + 0.01 * np.random.default_rng(0).standard_normal(len(frame))
    path = _write(frame, tmp_path / "flat.parquet")
    with pytest.warns(RawDataWarning, match="no state change in 200001 samples"):
        result = preprocess_raw(path, _settings(encoder_levels=(0.1, 1.7, 3.2, 4.8)))
    assert np.all(result.recording.position == 0.0)


def test_encoder_that_visits_three_states_is_an_error(small, tmp_path):
    frame = small[0].copy()
    levels = np.sort(frame["encoder"].to_numpy())
    frame["encoder"] = np.where(frame["encoder"] > levels[-1] - 0.8, levels[0], frame["encoder"])
    _fails(_write(frame, tmp_path / "three.parquet"), "only 3 of 4 levels")


@pytest.mark.parametrize("column, value, row", [("v2", -0.01, 1234), ("v1", 2.0, 77),
                                                ("v1", 0.0, 199_000)])
def test_bridge_voltage_outside_0_v0_is_an_error(small, tmp_path, column, value, row):
    frame = small[0].copy()
    frame.loc[row, column] = value
    _fails(_write(frame, tmp_path / "bad.csv"), f"column '{column}'", f"row {row + 1} ",
           f"(line {row + 2})", "outside (0, V0 = 2 V)", "eq. 4.3")


def test_clipped_channel_is_a_warning_with_counts(small, tmp_path):
    frame = small[0].copy()
    limit = frame["v1"].quantile(0.9)
    frame["v1"] = np.minimum(frame["v1"], limit)
    n = int((frame["v1"] == limit).sum())
    with pytest.warns(RawDataWarning, match=rf"column 'v1': {n} samples .* clipped"):
        result = preprocess_raw(_write(frame, tmp_path / "clip.parquet"), BRIDGE)
    assert result.report.clipped == {"v1_max": n}


def test_sample_rate_metadata_must_match_the_time_column(small, tmp_path):
    path = _write(small[0], tmp_path / "rate.parquet")
    _fails(path, "sampled at 100000 Hz", "fs = 200000 Hz", fmt=RawFormat(fs=2e5))
    wrong_unit = RawFormat(fs=1e5, time_unit="ms")  # seconds read as ms: 1000x too fast
    _fails(path, "sampled at 1e+08 Hz", "time_unit, now 'ms'", fmt=wrong_unit)


def test_missing_time_needs_fs(small, tmp_path):
    frame = small[0].drop(columns="time")
    path = _write(frame, tmp_path / "notime.parquet")
    _fails(path, "missing required column(s) 'time'")
    result = preprocess_raw(path, BRIDGE, RawFormat(fs=1e5))
    assert result.recording.n_samples == 81


def test_truncated_csv_is_an_error(small, tmp_path):
    path = _write(small[0], tmp_path / "cut.csv")
    text = path.read_bytes()
    path.write_bytes(text[:len(text) // 2].rsplit(b",", 1)[0])  # cut inside a line
    _fails(path, "missing or NaN value", "truncated")


def test_truncated_parquet_is_an_error(small, tmp_path):
    path = _write(small[0], tmp_path / "cut.parquet")
    path.write_bytes(path.read_bytes()[:-1000])
    _fails(path, "truncated")


def test_fewer_samples_than_the_settings_say(small, tmp_path):
    path = _write(small[0].iloc[:150_000], tmp_path / "short.parquet")
    _fails(path, "150000 samples but the settings say n_samples = 200001", "truncated",
           fmt=RawFormat(n_samples=200_001))


def test_dropped_samples_are_an_error(small, tmp_path):
    frame = small[0].drop(index=range(5000, 5010))
    _fails(_write(frame, tmp_path / "gap.csv"), "column 'time', row 5001 (line 5002)",
           "a gap of 10 samples")


def test_non_numeric_cell_is_an_error(small, tmp_path):
    path = _write(small[0], tmp_path / "text.csv")
    lines = path.read_text().splitlines()
    cells = lines[3001].split(",")
    cells[2] = "0.6x"
    lines[3001] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    _fails(path, "column 'v2', row 3001 (line 3002)", "non-numeric value '0.6x'")


def test_too_many_illegal_transitions_refuse_the_position(small, tmp_path):
    frame = small[0].iloc[::40].reset_index(drop=True)  # 2.5 kHz: states are missed
    _fails(_write(frame, tmp_path / "slow.parquet"), "illegal double transitions",
           "cannot be trusted")


def test_missing_columns_are_named(small, tmp_path):
    path = _write(small[0].drop(columns="encoder"), tmp_path / "noenc.csv")
    _fails(path, "missing required column(s)", "'encoder' or 'enc_a' and 'enc_b'")


# --------------------------------------------------------------------------- CLI


def test_cli_simulate_raw_preprocess_fit_evaluate(tmp_path, capsys):
    raw, data, model = tmp_path / "run.parquet", tmp_path / "run.csv", tmp_path / "m.json"
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "1", "--raw",
                 "--scope-rate", "20000", "--out", str(raw), "--truth",
                 str(tmp_path / "truth.csv")]) == 0
    assert main(["preprocess", str(raw), "--out", str(data)]) == 0
    out = capsys.readouterr().out
    assert "settings from" in out and "0 illegal" in out and f"wrote {data}" in out
    rec = read_recording(data)
    truth = read_recording(tmp_path / "truth.csv")
    assert rec.n_samples == 8000 and np.max(np.abs(rec.position - truth.position)) < COUNT_MM
    assert set(pd.read_csv(data, nrows=1).columns) == {"time", "position", "sensor", "r1",
                                                       "r2", "dr1", "dr2"}
    assert (tmp_path / "run.json").exists()
    assert main(["fit", str(data), "--cells", "1", "--out", str(model)]) == 0
    assert main(["evaluate", str(model), str(data)]) == 0
    assert "R²" in capsys.readouterr().out


def test_cli_prints_warnings_on_one_line(tmp_path, capsys):
    raw = tmp_path / "g.parquet"
    assert main(["simulate-sensor", "--excitation", "sine", "--raw", "--scope-rate", "2e5",
                 "--duration", "3", "--glitches", "3", "--out", str(raw)]) == 0
    assert main(["preprocess", str(raw), "--out", str(tmp_path / "g.csv")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("hystkit: warning: ")
    assert "3 illegal double transition(s)" in err[0]


def test_cli_needs_the_bridge_settings(small, tmp_path, capsys):
    path = _write(small[0], tmp_path / "bare.csv")  # no .toml beside it
    assert main(["preprocess", str(path), "--out", str(tmp_path / "o.csv")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--r-bridge" in err
    assert main(["preprocess", str(path), "--out", str(tmp_path / "o.csv"), "--r-bridge",
                 "1e4", "--v-supply", "2", "--cutoff", "25"]) == 2
    assert "above fs_out / 2" in capsys.readouterr().err
    assert main(["preprocess", str(path), "--out", str(tmp_path / "o.csv"), "--r-bridge",
                 "1e4", "--v-supply", "2"]) == 0


def test_cli_rejects_a_bad_settings_file(small, tmp_path, capsys):
    path = _write(small[0], tmp_path / "x.csv")
    (tmp_path / "x.toml").write_text("r_bridge = 1e4\nv_suply = 2\n")
    assert main(["preprocess", str(path), "--out", str(tmp_path / "o.csv")]) == 2
    assert "unknown key 'v_suply'" in capsys.readouterr().err
    (tmp_path / "x.toml").write_text("r_bridge = '10k'\nv_supply = 2\n")
    assert main(["preprocess", str(path), "--out", str(tmp_path / "o.csv")]) == 2
    assert "key 'r_bridge' must be int or float" in capsys.readouterr().err


def test_cli_raw_only_options_need_raw(tmp_path, capsys):
    assert main(["simulate-sensor", "--excitation", "sine", "--scope-rate", "1e6",
                 "--out", str(tmp_path / "x.csv")]) == 2
    assert "only apply with --raw" in capsys.readouterr().err
    assert not (tmp_path / "x.csv").exists()


# --------------------------------------------------------------------------- demo


def test_demo_raw_path_round_trip():
    from hystkit.studies._demo import run_raw_path

    lines = []
    raw = run_raw_path(1, scope_rate=2e4, progress=lines.append)
    assert raw["metrics"]["r2"] > 0.99 and raw["metrics"]["linear_r2"] < 0.97
    for trip in raw["round_trip"].values():
        assert trip["position_max_error_counts"] < 1 and trip["n_illegal"] == 0
        assert trip["sensor_rms_error"] < SENSOR_NOISE / 2
    assert raw["preprocess"]["n_samples"] == 3_999_951 and "raw path" in lines[0]


def test_demo_raw_flag_prints_the_raw_path(tmp_path, capsys, monkeypatch):
    from hystkit.cli import cmd_simulate

    canned = {"metrics": {}, "noise_trained": {}, "config": {},
              "raw_path": {"excitation": "sine", "scope_rate_hz": 5e4,
                           "metrics": {"r2": 0.99, "linear_r2": 0.93, "e_rms_pct": 1.0,
                                       "loop_area": 0.1, "center": "fit", "r2_oracle": 0.991,
                                       "linear_r2_oracle": 0.931},
                           "round_trip": {"validation": {
                               "position_max_error_um": 0.4, "position_max_error_counts": 0.08,
                               "sensor_rms_error": 4e-5, "n_illegal": 0, "n_edges": 240000}}}}
    calls = []
    monkeypatch.setattr(cmd_simulate, "demo_study",
                        lambda out, **kw: calls.append(kw) or canned)
    assert main(["demo", "--out", str(tmp_path), "--cells", "1", "--raw"]) == 0
    out = capsys.readouterr().out
    assert calls[0]["raw"] is True
    assert "sine raw" in out and "0 illegal of 240000" in out and "raw_path.json" in out
