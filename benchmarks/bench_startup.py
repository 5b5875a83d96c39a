"""Start-up time of the ``hystkit`` command line against its floor and against the work itself.

Run:  python benchmarks/bench_startup.py [--repeats N] [--out FILE]   (a few minutes)

Whole-process wall time, from starting ``python -m hystkit ...`` to its exit, of

- commands that do (almost) no work, so what is measured is the import and parser cost every
  command pays: ``--version``, ``--help``, ``fit --help``, and ``evaluate`` of a missing model
  file (one error line); issue 11 asks for ``--help``/``--version`` within 3x of
  ``python -c "import numpy"``, the floor any numpy program pays;
- ``hystkit fit`` of 8000 samples (the virtual sensor's noise recording, 40 Hz) with 1 and 3
  mPL cells, warm caches (file cache, numba's on-disk cache); issue 11 asks for the 1-cell fit
  within 2x of the fit itself. Two yardsticks for "the fit itself":

  * the fit inside the same process: ``fit 1 cell (timed)`` runs the very command (as the
    program: ``hystkit.cli.program()`` on ``sys.argv``) with ``fit_compensator`` wrapped in a
    timer; that first fit includes what a fresh process must do before its first fit can run
    (numba loading the cached kernels). Its row compares the process's wall time with it;
  * the warm fit: ``fit_compensator`` on the same recording in this (benchmark) process,
    kernels loaded long ago (``/ in-proc`` columns of the ``fit`` rows).

``fit 1 cell`` and ``evaluate`` are run a second time with Python's default garbage collector
instead of the program's setting (``hystkit.cli._main``: higher full-collection threshold, heap
frozen before shutdown), the one start-up setting the program keeps: the line below the table
says what it saves, paired round by round.

Below the table, what a fresh process pays before any hystkit code runs (its floor):
``import numpy, numba``, and that plus numba made ready to load cached kernels (its target
context: every implementation registry and scipy.linalg, which numba needs for LAPACK), the
step every first call of a cached kernel takes.

Children run with Python's bytecode cache (in a temporary ``PYTHONPYCACHEPREFIX``, filled by
the warm-up round), as an installed package does, even if ``PYTHONDONTWRITEBYTECODE`` is set
here (``--no-bytecode-cache`` measures without: every hystkit module compiled from source).

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
    "evaluate": ["-m", "hystkit", "evaluate", "m1.json", "fit.csv"],
}
# The program's one start-up setting (issue 28: a trick stays only if it saves >= 10 % of a common
# command): its garbage-collector thresholds and frozen heap at the end (hystkit.cli._main), undone.
GC_DEFAULT = ("import gc, sys\nimport hystkit.cli._main as program\n"
              "program._PROGRAM_GC_THRESHOLDS = gc.get_threshold()\n"
              "gc.freeze = lambda: None\nsys.argv = ['hystkit', *{argv!r}]\nprogram.program()")
WITH_GC_DEFAULT = ("fit 1 cell", "evaluate")
IN_PROCESS = {"fit 1 cell": 1, "fit 3 cells": 3}  # command -> cells of the in-process fit
NUMBA_FLOORS = {
    "import numpy, numba": "import numpy, numba",
    "  + numba ready (refresh)": ("import numpy, numba\nfrom numba.core.registry import cpu_target\n"
                                  "cpu_target.target_context.refresh()"),
}
TIMED = "fit 1 cell (timed)"
# The 1-cell fit as the program, timing fit_compensator inside it (seconds into FIT_SECONDS).
TIMED_FIT = """
import os, sys, time
import hystkit.compensation as compensation

def timed_fit(*args, **kwargs):
    from hystkit.compensation._fitting import fit_compensator  # the command imports it first
    start, cpu = time.perf_counter(), time.process_time()
    try:
        return fit_compensator(*args, **kwargs)
    finally:
        with open(os.environ["FIT_SECONDS"], "w") as out:
            out.write(f"{time.perf_counter() - start!r} {time.process_time() - cpu!r}")

compensation.fit_compensator = timed_fit
from hystkit.cli import program
sys.argv = ["hystkit", "fit", "fit.csv", "--size", "1", "--out", "m1t.json", "--force"]
program()
"""


def _machine() -> str:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"platform {platform.platform()}; cpus {os.cpu_count()}; load average {load}\n"
            f"python {platform.python_version()} ({sys.executable})")


def _child_env(cwd: Path, bytecode_cache: bool) -> dict[str, str]:
    env = dict(os.environ, FIT_SECONDS=str(cwd / "fit_seconds.txt"))
    if bytecode_cache:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(cwd / "pycache")
    return env


def _run(argv: list[str], cwd: Path, times: dict[str, float], label: str,
         env: dict[str, str]) -> None:
    """Wall time and CPU time (user + system of the child) of one process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, *argv], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, check=False, cwd=cwd, env=env)
    times[label] = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    times[f"cpu {label}"] = (after.ru_utime - before.ru_utime) + (after.ru_stime
                                                                  - before.ru_stime)


def _round(cwd: Path, recording, env: dict[str, str]) -> dict[str, float]:
    from hystkit.compensation import fit_compensator

    times: dict[str, float] = {}
    _run(FLOOR, cwd, times, "floor", env)
    for label, argv in COMMANDS.items():
        _run(argv, cwd, times, label, env)
        if label in WITH_GC_DEFAULT:
            _run(["-c", GC_DEFAULT.format(argv=argv[2:])], cwd, times, f"{label} (gc default)",
                 env)
    _run(["-c", TIMED_FIT], cwd, times, TIMED, env)
    for label, code in NUMBA_FLOORS.items():
        _run(["-c", code], cwd, times, label, {**env, "OPENBLAS_NUM_THREADS": "1"})
    wall, cpu = Path(env["FIT_SECONDS"]).read_text().split()
    times[f"in-process {TIMED}"], times[f"cpu in-process {TIMED}"] = float(wall), float(cpu)
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
    parser.add_argument("--no-bytecode-cache", action="store_true",
                        help="children compile every module from source (no .pyc files)")
    args = parser.parse_args()
    from hystkit.io import write_recording
    from hystkit.sensors import simulate_experiment

    title = (f"hystkit start-up: whole-process wall time [s], median of {args.repeats} "
             f"interleaved rounds (after 1 warm-up)")
    cache = ("without bytecode cache (every module compiled from source)"
             if args.no_bytecode_cache else "with bytecode cache (.pyc), as installed")
    lines = [title, _machine(), f"children {cache}", ""]
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        env = _child_env(cwd, not args.no_bytecode_cache)
        recording = simulate_experiment("noise", seed=1)
        write_recording(recording, cwd / "fit.csv")
        _round(cwd, recording, env)  # warm-up: file and bytecode caches, this process's JIT
        rounds = [_round(cwd, recording, env) for _ in range(args.repeats)]
    med = {key: statistics.median(r[key] for r in rounds) for key in rounds[0]}

    def ratio(key: str, ref: str) -> float:
        return statistics.median(r[key] / r[ref] for r in rounds)

    lines.append(f"{'':<27}{'wall time':^30}|{'CPU time (user + sys)':^30}")
    lines.append(f"{'command':<27}{'median s':>10}{'/ numpy':>9}{'/ in-proc':>11}|"
                 f"{'median s':>10}{'/ numpy':>9}{'/ in-proc':>11}")
    for label in ("floor", *COMMANDS):
        name = 'python -c "import numpy"' if label == "floor" else f"hystkit {label}"
        row = f"{name:<27}"
        for prefix in ("", "cpu "):
            key, ref = f"{prefix}{label}", f"{prefix}in-process {label}"
            vs_fit = f"{ratio(key, ref):>10.2f}x" if label in IN_PROCESS else f"{'':>11}"
            row += (f"{med[key]:>10.3f}{ratio(key, f'{prefix}floor'):>8.2f}x{vs_fit}"
                    + ("|" if not prefix else ""))
        lines.append(row)
    lines.append(f"{'hystkit ' + TIMED:<27}{med[TIMED]:>10.3f}"
                 f"{ratio(TIMED, 'floor'):>8.2f}x{ratio(TIMED, 'in-process ' + TIMED):>10.2f}x|"
                 f"{med['cpu ' + TIMED]:>10.3f}{ratio('cpu ' + TIMED, 'cpu floor'):>8.2f}x"
                 f"{ratio('cpu ' + TIMED, 'cpu in-process ' + TIMED):>10.2f}x")
    key = f"in-process {TIMED}"
    lines.append(f"{'  its first fit':<27}{med[key]:>10.3f}{'':>20}|{med['cpu ' + key]:>10.3f}"
                 f"   (fit_compensator in that process, loading its kernels)")
    for label in IN_PROCESS:
        key = f"in-process {label}"
        lines.append(f"{key:<27}{med[key]:>10.3f}{'':>20}|{med['cpu ' + key]:>10.3f}"
                     f"   (fit_compensator warm, {recording.n_samples} samples)")
    for label in NUMBA_FLOORS:
        lines.append(f"{label:<27}{med[label]:>10.3f}{ratio(label, 'floor'):>8.2f}x{'':>11}|"
                     f"{med['cpu ' + label]:>10.3f}{ratio('cpu ' + label, 'cpu floor'):>8.2f}x")
    for label in WITH_GC_DEFAULT:
        lines.append(f"{label}, Python's default garbage collector instead of the program's: "
                     f"{med[label + ' (gc default)']:.3f} s, the setting saves "
                     f"{1 - ratio(label, label + ' (gc default)'):.0%} of the wall time, "
                     f"{1 - ratio('cpu ' + label, 'cpu ' + label + ' (gc default)'):.0%} of the CPU")
    lines.append(f"fit 1 cell vs the warm fit: {ratio(TIMED, 'in-process fit 1 cell'):.1f}x "
                 f"(timed run), {ratio('fit 1 cell', 'in-process fit 1 cell'):.1f}x (plain run)")
    lines.append(f"load average after: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    report = "\n".join(lines)
    print(report)
    if args.out is not None:
        args.out.write_text(report + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
