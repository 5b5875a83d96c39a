"""Hostile raw recordings and settings: ``hystkit preprocess`` and ``simulate-sensor --raw``.

Every bad raw file or TOML key is one ``hystkit: error:`` line naming the file (and the key or
column), exit 2, nothing written; the chunk size never changes a result (split run == whole
run, bit for bit); a killed ``simulate-sensor --raw`` leaves nothing behind.
"""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from .conftest import entries, snapshot

# The virtual sensor's bridge: what simulate-sensor --raw writes into its settings.
BRIDGE = "r_bridge = 10000.0\nv_supply = 2.0\n"


@pytest.fixture(scope="module")
def raw(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small raw recording (0.1 s at 10 kHz, 1001 samples) and its settings file."""
    from hystkit.cli import main

    folder = tmp_path_factory.mktemp("raw")
    path = folder / "scope.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--raw", "--duration", "0.1",
                 "--scope-rate", "10000", "--out", str(path)]) == 0
    return path


def _copy(raw: Path, folder: Path, lines: int | None = None) -> Path:
    """The raw file (its first `lines` lines) in `folder`, without its settings file."""
    target = folder / "scope.csv"
    if lines is None:
        shutil.copy(raw, target)
    else:
        text = raw.read_text().splitlines(keepends=True)
        target.write_text("".join(text[:lines]))
    return target


def _refused(cli, folder: Path, argv: list, *fragments: object) -> str:
    before = snapshot(folder)
    run = cli(*argv)
    assert run.code == 2, run.err
    line = run.error_line(*fragments)
    assert snapshot(folder) == before
    return line


# ------------------------------------------------------------------ chunk size


def test_chunk_size_never_changes_the_result(cli, raw, tmp_path):
    """Chunks of 1, 2, 3, 10 and 997 samples (TOML ``chunk_size``), 1024 (the option) and the
    default give byte-identical output files."""
    data = _copy(raw, tmp_path)
    outputs = {}
    for size in (1, 2, 3, 10, 997, 1024, None):
        config = tmp_path / f"c{size}.toml"
        config.write_text(BRIDGE + (f"chunk_size = {size}\n" if size not in (None, 1024)
                                    else ""))
        out = tmp_path / f"out{size}.csv"
        argv = ["preprocess", data, "--config", config, "--out", out]
        run = cli(*argv, *(["--chunk-size", 1024] if size == 1024 else []))
        assert run.code == 0, run.err
        outputs[size] = out.read_bytes()
    assert len(outputs[None]) > 100
    for size, content in outputs.items():
        assert content == outputs[None], f"chunk size {size} changed the result"


# ------------------------------------------------------------------ short files


def test_three_row_raw_file(cli, raw, tmp_path):
    data = _copy(raw, tmp_path, lines=4)
    config = tmp_path / "s.toml"
    config.write_text(BRIDGE)
    _refused(cli, tmp_path, ["preprocess", data, "--config", config, "--out",
                             tmp_path / "o.csv"], "scope.csv", "encoder", "3 samples")


def test_three_row_raw_file_with_given_levels(cli, raw, tmp_path):
    data = _copy(raw, tmp_path, lines=4)
    config = tmp_path / "s.toml"
    config.write_text(BRIDGE + "encoder_levels = [0.1, 1.68, 3.21, 4.79]\n")
    _refused(cli, tmp_path, ["preprocess", data, "--config", config, "--out",
                             tmp_path / "o.csv"], "scope.csv", "too short")


def test_header_only_raw_file(cli, raw, tmp_path):
    data = _copy(raw, tmp_path, lines=1)
    config = tmp_path / "s.toml"
    config.write_text(BRIDGE)
    _refused(cli, tmp_path, ["preprocess", data, "--config", config, "--out",
                             tmp_path / "o.csv"], "scope.csv")


# (case id, column index, cell text, fragments besides the file, column and row)
CELL_CASES = [
    ("v1-inf", 1, "inf", ["infinite"]),
    ("v1-denormal", 1, "1e-320", ["bridge voltage"]),
    ("v2-zero", 2, "0", ["bridge voltage"]),
    ("v1-above-supply", 1, "5.0", ["bridge voltage"]),
    ("encoder-huge", 3, "1e308", ["not a scope reading"]),
    ("encoder-huge-negative", 3, "-1.7e308", ["not a scope reading"]),
    ("encoder-nan", 3, "nan", ["nan"]),
    ("encoder-text", 3, "abc", ["abc"]),
    ("time-huge", 0, "1e308", ["gap"]),
]
_COLUMNS = ("time", "v1", "v2", "encoder")


@pytest.mark.parametrize("index, cell, fragments", [c[1:] for c in CELL_CASES],
                         ids=[c[0] for c in CELL_CASES])
def test_bad_cell_is_named_by_column_and_row(cli, raw, tmp_path, index, cell, fragments):
    data = _copy(raw, tmp_path)
    lines = data.read_text().splitlines(keepends=True)
    cells = lines[500].rstrip("\n").split(",")
    cells[index] = cell
    lines[500] = ",".join(cells) + "\n"
    data.write_text("".join(lines))
    config = tmp_path / "s.toml"
    config.write_text(BRIDGE)
    _refused(cli, tmp_path, ["preprocess", data, "--config", config, "--out",
                             tmp_path / "o.csv"], "scope.csv", _COLUMNS[index],
             "row 500 (line 501)", *fragments)


# ------------------------------------------------------------------ settings files

# (case id, TOML text, fragments of the error line besides the file name)
CONFIG_CASES = [
    ("skip-rows-huge", BRIDGE + "skip_rows = 1000000000\n", ["skip_rows", "outside"]),
    ("skip-rows-negative", BRIDGE + "skip_rows = -1\n", ["skip_rows"]),
    ("r-bridge-nan", "r_bridge = nan\nv_supply = 2.0\n", ["r_bridge", "finite"]),
    ("v-supply-inf", "r_bridge = 1e4\nv_supply = inf\n", ["v_supply", "finite"]),
    ("v-supply-zero", "r_bridge = 1e4\nv_supply = 0.0\n", ["v_supply", "outside"]),
    ("fs-huge", BRIDGE + "fs = 1e300\n", ["fs", "outside"]),
    ("chunk-size-zero", BRIDGE + "chunk_size = 0\n", ["chunk_size", "outside"]),
    ("chunk-size-huge", BRIDGE + "chunk_size = 10000000000000\n", ["chunk_size"]),
    ("order-huge", BRIDGE + "order = 1000\n", ["order", "outside"]),
    ("n-samples-negative", BRIDGE + "n_samples = -5\n", ["n_samples"]),
    ("cutoff-negative", BRIDGE + "cutoff = -20.0\n", ["cutoff"]),
    ("levels-two", BRIDGE + "encoder_levels = [1.0, 2.0]\n", ["encoder_levels", "four"]),
    ("levels-nan", BRIDGE + "encoder_levels = [0.1, nan, 3.2, 4.8]\n", ["encoder_levels"]),
    ("illegal-choice", BRIDGE + 'illegal = "maybe"\n', ["illegal", "continue"]),
    ("time-unit", BRIDGE + 'time_unit = "fortnights"\n', ["time_unit"]),
    ("columns-unknown", BRIDGE + '[columns]\nbogus = "x"\n', ["columns", "bogus"]),
    ("wrong-type", BRIDGE + 'fs_out = "forty"\n', ["fs_out"]),
    ("unknown-key", BRIDGE + "r_bridg = 3\n", ["r_bridg", "unknown"]),
    ("invalid-toml", "r_bridge = = 3\n", ["invalid TOML"]),
]


@pytest.mark.parametrize("text, fragments", [c[1:] for c in CONFIG_CASES],
                         ids=[c[0] for c in CONFIG_CASES])
def test_bad_settings_name_file_and_key(cli, raw, tmp_path, text, fragments):
    data = _copy(raw, tmp_path)
    config = tmp_path / "bad.toml"
    config.write_text(text)
    _refused(cli, tmp_path, ["preprocess", data, "--config", config, "--out",
                             tmp_path / "o.csv"], "bad.toml", *fragments)


def test_binary_settings_file(cli, raw, tmp_path):
    data = _copy(raw, tmp_path)
    config = tmp_path / "bad.toml"
    config.write_bytes(bytes(range(256)))
    _refused(cli, tmp_path, ["preprocess", data, "--config", config, "--out",
                             tmp_path / "o.csv"], "bad.toml")


def test_settings_folder(cli, raw, tmp_path):
    data = _copy(raw, tmp_path)
    (tmp_path / "conf").mkdir()
    _refused(cli, tmp_path, ["preprocess", data, "--config", tmp_path / "conf", "--out",
                             tmp_path / "o.csv"], "conf", "folder")


def test_settings_beside_the_data_are_checked_too(cli, raw, tmp_path):
    """The default settings file (the data's stem) gets the same checks as --config."""
    data = _copy(raw, tmp_path)
    (tmp_path / "scope.toml").write_text(BRIDGE + "skip_rows = 1000000000\n")
    _refused(cli, tmp_path, ["preprocess", data, "--out", tmp_path / "o.csv"],
             "scope.toml", "skip_rows")


# ------------------------------------------------------------------ simulate-sensor --raw


def test_simulate_raw_writes_data_and_settings_and_no_temporaries(cli, tmp_path):
    run = cli("simulate-sensor", "--excitation", "sine", "--raw", "--duration", "0.05",
              "--scope-rate", "10000", "--out", tmp_path / "s.parquet")
    assert run.code == 0, run.err
    assert entries(tmp_path) == ["s.parquet", "s.toml"]


def test_simulate_raw_refuses_existing_settings_and_writes_nothing(cli, tmp_path):
    (tmp_path / "s.toml").write_text("# mine\n")
    _refused(cli, tmp_path, ["simulate-sensor", "--excitation", "sine", "--raw", "--duration",
                             "0.05", "--scope-rate", "10000", "--out", tmp_path / "s.csv"],
             "s.toml", "exists")
    assert entries(tmp_path) == ["s.toml"]


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_killed_simulate_raw_leaves_nothing(tmp_path):
    """SIGTERM in the middle of a long raw simulation: exit 143, no data file, no settings,
    no temporary."""
    proc = subprocess.Popen([sys.executable, "-m", "hystkit", "simulate-sensor",
                             "--excitation", "sine", "--raw", "--duration", "20",
                             "--out", str(tmp_path / "big.csv")], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not any(p.name.startswith(".big") for p in tmp_path.iterdir()):  # writing started
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    time.sleep(0.3)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert "Traceback" not in err
    assert entries(tmp_path) == []


# ------------------------------------------------------------------ damaged .mat raw files


@pytest.fixture(scope="module")
def raw_mat(raw: Path) -> bytes:
    """The small raw recording as MATLAB bytes."""
    import io

    import pandas as pd
    from scipy.io import savemat

    table = pd.read_csv(raw)
    buffer = io.BytesIO()
    savemat(buffer, {c: table[c].to_numpy() for c in table.columns})
    return buffer.getvalue()


@pytest.mark.parametrize("seed", range(8))
def test_byte_mutated_mat_raw_file(cli, raw_mat, tmp_path, seed):
    """One byte of the header or first variable changed: a result or one error line naming
    the file, never a crash (the .mat is parsed in a child process)."""
    rng = np.random.default_rng(seed)
    data = bytearray(raw_mat)
    data[int(rng.integers(116, 600))] = int(rng.integers(0, 256))
    path = tmp_path / "scope.mat"
    path.write_bytes(bytes(data))
    (tmp_path / "scope.toml").write_text(BRIDGE)
    before = snapshot(tmp_path)
    run = cli("preprocess", path, "--out", tmp_path / "o.csv")
    run.clean()
    if run.code != 0:
        assert run.code == 2, run.err
        run.error_line("scope.mat")
        assert snapshot(tmp_path) == before


def test_truncated_mat_raw_file(cli, raw_mat, tmp_path):
    path = tmp_path / "scope.mat"
    path.write_bytes(raw_mat[: len(raw_mat) // 2])
    (tmp_path / "scope.toml").write_text(BRIDGE)
    _refused(cli, tmp_path, ["preprocess", path, "--out", tmp_path / "o.csv"], "scope.mat")


# ------------------------------------------------------------------ Parquet raw files


def _parquet_null(table):
    import pyarrow as pa

    values = table.column("v1").to_pylist()
    values[300] = None
    return table.set_column(1, "v1", pa.array(values, type=pa.float64()))


def _parquet_strings(table):
    import pyarrow as pa

    return table.set_column(1, "v1", pa.array([str(v) for v in table.column("v1").to_pylist()]))


PARQUET_CASES = [
    ("null-cell", _parquet_null, ["v1", "row 301"]),
    ("string-column", _parquet_strings, ["v1", "not numeric"]),
    ("no-rows", lambda t: t.slice(0, 0), ["fewer than 2 samples"]),
    ("three-rows", lambda t: t.slice(0, 3), ["encoder", "3 samples"]),
]


@pytest.mark.parametrize("change, fragments", [c[1:] for c in PARQUET_CASES],
                         ids=[c[0] for c in PARQUET_CASES])
def test_bad_parquet_raw_file(cli, raw, tmp_path, change, fragments):
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    path = tmp_path / "scope.parquet"
    pq.write_table(change(pa_csv.read_csv(raw)), path)
    (tmp_path / "scope.toml").write_text(BRIDGE)
    _refused(cli, tmp_path, ["preprocess", path, "--out", tmp_path / "o.csv"], "scope.parquet",
             *fragments)
