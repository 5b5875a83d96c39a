"""Fuzzing the recording readers: byte-mutated CSV, Parquet and MATLAB files (issue 10).

Hypothesis draws mutations (bit flips, byte changes, inserts, deletes, long runs, truncation)
of valid files; every mutated file is read by ``read_recording`` in a worker process, so a
segfault or a hang is caught rather than taking pytest down. The only allowed outcomes are a
`Recording` or one `InputError` line naming the file; anything else (another exception, a
signal, no answer within the time limit) is an escape, and the test fails listing them.

One worker reads many files (one outcome per line); when it dies on a file, that file is
recorded and a new worker continues with the rest. ``.mat`` files cost an interpreter start
each (the reader parses them in a child process), so fewer are tried.

Environment: ``HYSTKIT_FUZZ_EXAMPLES`` (default 150) mutated files per format for CSV and
Parquet, ``HYSTKIT_FUZZ_MAT_EXAMPLES`` (default 20) for ``.mat``; ``HYSTKIT_FUZZ_WORKERS``
(default 1) workers in parallel. A campaign::

    HYSTKIT_FUZZ_EXAMPLES=5000 HYSTKIT_FUZZ_MAT_EXAMPLES=1000 HYSTKIT_FUZZ_WORKERS=2 \\
        python -m pytest -q -s tests/hostile/test_reader_fuzz.py
"""

from __future__ import annotations

import os
import selectors
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.io import savemat

from hystkit.io import Recording, write_recording

EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "150"))
MAT_EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_MAT_EXAMPLES", "20"))
WORKERS = int(os.environ.get("HYSTKIT_FUZZ_WORKERS", "1"))
FILE_TIMEOUT_S = 90.0  # per file; the .mat reader's own limit is 30 s plus size

# The worker: reads file paths from stdin, answers "START i" before and one outcome after each.
_WORKER = r"""
import sys
from hystkit.errors import InputError
from hystkit.io import Recording, read_recording
for i, line in enumerate(sys.stdin):
    path = line.rstrip("\n")
    print("START", i, flush=True)
    try:
        rec = read_recording(path)
        assert isinstance(rec, Recording)
        outcome = "ok"
    except InputError as exc:
        text = str(exc)
        good = text.startswith(path + ": ") and "\n" not in text and "Traceback" not in text
        outcome = "input" if good else "escape bad-message " + repr(text)[:300]
    except BaseException as exc:
        outcome = "escape " + type(exc).__name__ + ": " + repr(str(exc))[:300]
    print("DONE", i, outcome, flush=True)
"""


def _valid_recording(n: int = 60) -> Recording:
    time_s = np.arange(n) * 0.025
    position = np.sin(2 * np.pi * 0.5 * time_s) * 3.0
    return Recording(time=time_s, sensor=0.01 * position + 1e-4 * np.cos(time_s),
                     position=position)


def _seeds(folder: Path) -> dict[str, list[bytes]]:
    rec = _valid_recording()
    write_recording(rec, folder / "seed.csv")
    write_recording(rec, folder / "seed.parquet")
    columns = {"time": rec.time, "position": rec.position, "sensor": rec.sensor}
    savemat(folder / "plain.mat", columns)
    savemat(folder / "zipped.mat", columns, do_compression=True)
    return {".csv": [(folder / "seed.csv").read_bytes()],
            ".parquet": [(folder / "seed.parquet").read_bytes()],
            ".mat": [(folder / "plain.mat").read_bytes(), (folder / "zipped.mat").read_bytes()]}


_OPS = st.one_of(
    st.tuples(st.just("flip"), st.integers(0, 1 << 30), st.integers(0, 7)),
    st.tuples(st.just("set"), st.integers(0, 1 << 30), st.sampled_from([0, 0xFF, 0x7F, 0x80,
                                                                         0x22, 0x2C, 0x0A])),
    st.tuples(st.just("insert"), st.integers(0, 1 << 30), st.binary(min_size=1, max_size=8)),
    st.tuples(st.just("delete"), st.integers(0, 1 << 30), st.integers(1, 16)),
    st.tuples(st.just("run"), st.integers(0, 1 << 30),
              st.tuples(st.sampled_from(b'9"\x00,\n\xff'), st.integers(1, 200_000))),
    st.tuples(st.just("truncate"), st.integers(0, 1 << 30), st.just(0)),
)
# Headers and tags sit at the start of CSV and .mat files, Parquet's metadata at the end: a
# third of the mutations fall in the first 512 bytes, a third in the last 512.
_MUTATIONS = st.tuples(st.integers(0, 1), st.sampled_from(["start", "anywhere", "end"]),
                       st.lists(_OPS, min_size=1, max_size=4))


def _mutate(seed: bytes, region: str, ops: list[tuple]) -> bytes:
    data = bytearray(seed)
    for op, position, arg in ops:
        span = len(data) if region == "anywhere" else min(len(data), 512)
        at = position % max(span, 1)
        if region == "end":
            at = max(len(data) - 1 - at, 0)
        if op == "flip" and data:
            data[at] ^= 1 << arg
        elif op == "set" and data:
            data[at] = arg
        elif op == "insert":
            data[at:at] = arg
        elif op == "delete":
            del data[at:at + arg]
        elif op == "run":
            data[at:at] = bytes([arg[0]]) * arg[1]
        elif op == "truncate":
            del data[at:]
    return bytes(data)


def _collect(seeds: list[bytes], n: int) -> list[bytes]:
    """`n` mutated files drawn by hypothesis (collected first, read in bulk afterwards)."""
    out: list[bytes] = []

    @settings(max_examples=n, database=None, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(_MUTATIONS)
    def draw(mutation: tuple) -> None:
        which, region, ops = mutation
        out.append(_mutate(seeds[which % len(seeds)], region, ops))

    draw()
    return out


def _run_worker(paths: list[Path]) -> dict[int, str]:
    """Outcome per index of `paths`; a worker that dies or hangs is replaced."""
    outcomes: dict[int, str] = {}
    todo = list(range(len(paths)))
    while todo:
        current, outcome = _one_worker(paths, todo, outcomes)
        if current is not None:
            outcomes[current] = outcome
        elif not any(i in outcomes for i in todo):
            raise RuntimeError(f"fuzz worker failed before the first file: {outcome}")
        todo = [i for i in todo if i not in outcomes]
    return outcomes


def _one_worker(paths: list[Path], todo: list[int], outcomes: dict[int, str]
                ) -> tuple[int | None, str]:
    """Feed `todo` to one worker until it ends; returns the file it died on and how."""
    with subprocess.Popen([sys.executable, "-c", _WORKER], stdin=subprocess.PIPE,
                          stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                          env={**os.environ, "MPLBACKEND": "Agg"}) as proc:
        assert proc.stdin is not None and proc.stdout is not None
        proc.stdin.write("".join(f"{paths[i]}\n" for i in todo))
        proc.stdin.close()
        current: int | None = None
        deadline = time.monotonic() + FILE_TIMEOUT_S + 30  # the worker's own start-up
        with selectors.DefaultSelector() as selector:
            selector.register(proc.stdout, selectors.EVENT_READ)
            while True:
                if not selector.select(timeout=max(deadline - time.monotonic(), 0)):
                    proc.kill()
                    return current, f"escape hang (no answer within {FILE_TIMEOUT_S:g} s)"
                line = proc.stdout.readline()
                if not line:
                    code = proc.wait()
                    return current, f"escape worker died (exit {code})"
                kind, index, *rest = line.split(" ", 2)
                deadline = time.monotonic() + FILE_TIMEOUT_S
                if kind == "START":
                    current = todo[int(index)]
                else:
                    outcomes[current] = rest[0].strip()
                    current = None


def _fuzz(tmp_path: Path, suffix: str, n: int) -> None:
    seeds = _seeds(tmp_path)[suffix]
    files = []
    for i, data in enumerate(_collect(seeds, n)):
        path = tmp_path / f"m{i:05d}{suffix}"
        path.write_bytes(data)
        files.append(path)
    started = time.perf_counter()
    shares = [files[k::WORKERS] for k in range(WORKERS)]
    if WORKERS == 1:
        results = [_run_worker(files)]
    else:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(WORKERS) as pool:
            results = list(pool.map(_run_worker, shares))
    outcomes = {shares[k][i]: text for k, result in enumerate(results)
                for i, text in result.items()}
    counts = Counter(text.split(" ")[0] for text in outcomes.values())
    escapes = {str(path): text for path, text in outcomes.items() if text.startswith("escape")}
    print(f"\nfuzz {suffix}: {len(files)} mutated files in {time.perf_counter() - started:.1f} s:"
          f" {counts['ok']} read, {counts['input']} InputError, {len(escapes)} escapes")
    assert len(outcomes) == len(files)
    assert not escapes, "\n".join(f"{path}: {text}" for path, text in sorted(escapes.items()))


@pytest.mark.parametrize(("suffix", "n"), [(".csv", EXAMPLES), (".parquet", EXAMPLES),
                                           (".mat", MAT_EXAMPLES)])
def test_mutated_files_give_a_recording_or_one_input_error(tmp_path: Path, suffix: str,
                                                           n: int) -> None:
    _fuzz(tmp_path, suffix, n)
