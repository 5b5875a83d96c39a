"""Start-up time of the ``hystkit`` command line against its floor and against the work itself.

Run:  python benchmarks/bench_startup.py [--repeats N] [--out FILE]   (a few minutes)

Whole-process wall time, from starting ``python -m hystkit ...`` to its exit, of

- commands that do (almost) no work, so what is measured is the import and parser cost every
  command pays: ``--version``, ``--help``, ``fit --help``, and ``evaluate`` of a missing model
  file (one error line); issue 11 asks for ``--help``/``--version`` within 3x of
  ``python -c "import numpy"``, the floor any numpy program pays;
- ``hystkit fit`` of 8000 samples (the virtual sensor's noise recording, 40 Hz) with 1 and 3
  mPL cells, warm caches (file cache, numba's on-disk cache); issue 11 asks for the 1-cell fit
  within 2x of the fit itself, measured here in this process as ``fit_compensator`` on the same
  recording (what the command computes, without start-up, reading and writing).

Wall and CPU time (user + system of the child process) are both reported: on a shared machine
the wall time carries the other jobs' load, the CPU time much less. Paired and interleaved:
every repeat runs the floor, each command and the in-process fits once,
one after the other, so bursts of load hit all alike; reported are the medians and the median
of the per-repeat ratios. One warm-up round is not counted.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FLOOR = ["-c", "import numpy"]
COMMANDS = {
    "--version": ["-m", "hystkit", "--version"],
    "--help": ["-m", "hystkit", "--help"],
    "fit --help": ["-m", "hystkit", "fit", "--help"],
    "evaluate missing": ["-m", "hystkit", "evaluate", "missing-model.json", "missing.csv"],
    "fit 1 cell": ["-m", "hystkit", "fit", "fit.csv", "--size", "1", "--out", "m1.json",
                   "--force"],
    "fit 3 cells": ["-m", "hystkit", "fit", "fit.csv", "--size", "3", "--out", "m3.json",
                    "--force"],
}
IN_PROCESS = {"fit 1 cell": 1, "fit 3 cells": 3}  # command -> cells of the in-process fit


def _machine() -> str:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"platform {platform.platform()}; cpus {os.cpu_count()}; load average {load}\n"
            f"python {platform.python_version()} ({sys.executable})")


def _run(argv: list[str], cwd: Path, times: dict[str, float], label: str) -> None:
    """Wall time and CPU time (user + system of the child) of one process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, *argv], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, check=False, cwd=cwd)
    times[label] = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    times[f"cpu {label}"] = (after.ru_utime - before.ru_utime) + (after.ru_stime
                                                                  - before.ru_stime)


def _round(cwd: Path, recording) -> dict[str, float]:
    from hystkit.compensation import fit_compensator

    times: dict[str, float] = {}
    _run(FLOOR, cwd, times, "floor")
    for label, argv in COMMANDS.items():
        _run(argv, cwd, times, label)
    for label, cells in IN_PROCESS.items():
        t0, c0 = time.perf_counter(), time.process_time()
        fit_compensator(recording, cells)
        times[f"in-process {label}"] = time.perf_counter() - t0
        times[f"cpu in-process {label}"] = time.process_time() - c0
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--out", type=Path, default=None,
                        help="also write the report here (e.g. benchmarks/last_run_startup.txt)")
    args = parser.parse_args()
    from hystkit.io import write_recording
    from hystkit.sensors import simulate_experiment

    title = (f"hystkit start-up: whole-process wall time [s], median of {args.repeats} "
             f"interleaved rounds (after 1 warm-up)")
    lines = [title, _machine(), ""]
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        recording = simulate_experiment("noise", seed=1)
        write_recording(recording, cwd / "fit.csv")
        _round(cwd, recording)  # warm-up: file cache, numba cache, this process's JIT
        rounds = [_round(cwd, recording) for _ in range(args.repeats)]
    med = {key: statistics.median(r[key] for r in rounds) for key in rounds[0]}

    def ratio(key: str, ref: str) -> float:
        return statistics.median(r[key] / r[ref] for r in rounds)

    lines.append(f"{'':<24}{'wall time':^30}|{'CPU time (user + sys)':^30}")
    lines.append(f"{'command':<24}{'median s':>10}{'/ numpy':>9}{'/ in-proc':>11}|"
                 f"{'median s':>10}{'/ numpy':>9}{'/ in-proc':>11}")
    for label in ("floor", *COMMANDS):
        name = 'python -c "import numpy"' if label == "floor" else f"hystkit {label}"
        row = f"{name:<24}"
        for prefix in ("", "cpu "):
            key, ref = f"{prefix}{label}", f"{prefix}in-process {label}"
            vs_fit = f"{ratio(key, ref):>10.2f}x" if label in IN_PROCESS else f"{'':>11}"
            row += (f"{med[key]:>10.3f}{ratio(key, f'{prefix}floor'):>8.2f}x{vs_fit}"
                    + ("|" if not prefix else ""))
        lines.append(row)
    for label in IN_PROCESS:
        key = f"in-process {label}"
        lines.append(f"{key:<24}{med[key]:>10.3f}{'':>20}|{med['cpu ' + key]:>10.3f}"
                     f"   (fit_compensator, {recording.n_samples} samples)")
    lines.append(f"load average after: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    report = "\n".join(lines)
    print(report)
    if args.out is not None:
        args.out.write_text(report + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
