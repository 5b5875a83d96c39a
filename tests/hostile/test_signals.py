"""Ctrl-C and SIGTERM with real signals: one line, exit 130/143, nothing partial left.

Each case starts ``python -m hystkit`` in its own session, waits for a sign that the work (or
the writing) is under way rather than sleeping a fixed time, sends the signal, and checks the
exit code, that stderr is exactly one line (no traceback from the command or its workers), and
that the output folder holds no output and no temporary.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from .conftest import entries

MESSAGES = {signal.SIGINT: (130, "hystkit: interrupted"),
            signal.SIGTERM: (143, "hystkit: terminated (SIGTERM)")}


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(*argv: object, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "hystkit", *map(str, argv)], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True,  # its own group, like a terminal job
                            # a shell's background job (CI, nohup) ignores SIGINT, and the
                            # child would inherit that; a terminal's job has the default
                            preexec_fn=_default_sigint,  # noqa: PLW1509 (no threads here)
                            env={**os.environ, "MPLBACKEND": "Agg", "PYTHONUNBUFFERED": "1"})


def _wait_until(proc: subprocess.Popen, ready: Callable[[], bool], timeout: float = 120) -> None:
    t_end = time.monotonic() + timeout
    while not ready():
        assert proc.poll() is None, f"finished before the signal: {proc.communicate()}"
        assert time.monotonic() < t_end, "no sign of progress"
        time.sleep(0.005)


def _stopped(proc: subprocess.Popen, sig: signal.Signals) -> None:
    out, err = proc.communicate(timeout=120)
    assert "Traceback" not in out, out
    code, line = MESSAGES[sig]
    assert "Traceback" not in err, err
    assert err.splitlines() == [line], err
    assert proc.returncode == code


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["sigint", "sigterm"])
def test_demo_stopped_while_fitting_leaves_no_folder(sig: signal.Signals,
                                                     tmp_path: Path) -> None:
    proc = _start("demo", "--out", "D", cwd=tmp_path)
    assert proc.stdout.readline().startswith("hystkit demo:")  # started
    assert "fitted in" in proc.stdout.readline()  # first fit done: deep in the work
    proc.send_signal(sig)
    _stopped(proc, sig)
    assert entries(tmp_path) == []


@pytest.fixture(scope="module")
def long_recording(good: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A long recording, so that writing the compensated CSV takes a noticeable time."""
    n = 300_000
    sensor = pd.read_csv(good["val"])["sensor"].to_numpy()
    path = tmp_path_factory.mktemp("long") / "long.csv"
    pd.DataFrame({"time": np.arange(n) / 40.0, "sensor": np.resize(sensor, n)}).to_csv(
        path, index=False)
    return path


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["sigint", "sigterm"])
def test_compensate_stopped_while_writing_leaves_no_file(sig: signal.Signals, tmp_path: Path,
                                                          good: dict[str, Path],
                                                          long_recording: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.csv").write_text("an earlier result\n")
    proc = _start("compensate", good["model"], long_recording, "--out", "est.csv", cwd=out)
    # the hidden temporary appears when the writing starts: stop it exactly then
    _wait_until(proc, lambda: any(".tmp-" in name for name in os.listdir(out)))
    proc.send_signal(sig)
    _stopped(proc, sig)
    assert entries(out) == ["keep.csv"]
    assert (out / "keep.csv").read_text() == "an earlier result\n"


def _gone(pids: list[str], timeout: float = 10) -> bool:
    """Whether the processes ended (stopped workers take a moment once their parent exited)."""
    t_end = time.monotonic() + timeout
    while any(_running(p) for p in pids):
        if time.monotonic() > t_end:
            return False
        time.sleep(0.01)
    return True


def _running(pid: str) -> bool:
    try:  # a zombie waiting for its new parent to reap it has ended
        return Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


def _children(pid: int) -> list[str]:
    """Child processes of every thread of `pid` (Dask's nanny forks from its own thread)."""
    found = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found += (task / "children").read_text().split()
        except OSError:
            continue
    return found


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
def test_select_with_workers_ctrl_c_is_one_line(tmp_path: Path, good: dict[str, Path]) -> None:
    """Ctrl-C signals the whole process group: the workers end without tracebacks."""
    proc = _start("select", good["fit"], "--jobs", "2", "--out", "m.json", cwd=tmp_path)
    _wait_until(proc, lambda: len(_children(proc.pid)) >= 2)
    time.sleep(0.5)  # let the workers get into their candidates
    workers = _children(proc.pid)
    os.killpg(proc.pid, signal.SIGINT)
    _stopped(proc, signal.SIGINT)
    assert _gone(workers)
    assert entries(tmp_path) == []


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
def test_select_with_workers_sigterm_stops_them_too(tmp_path: Path,
                                                    good: dict[str, Path]) -> None:
    """SIGTERM to the parent alone: it terminates its workers instead of waiting for them."""
    proc = _start("select", good["fit"], "--jobs", "2", "--out", "m.json", cwd=tmp_path)
    _wait_until(proc, lambda: len(_children(proc.pid)) >= 2)
    workers = _children(proc.pid)
    t0 = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    _stopped(proc, signal.SIGTERM)
    assert time.monotonic() - t0 < 20
    assert _gone(workers)
    assert entries(tmp_path) == []
