"""Scaling of the parallel searches and of ``hystkit batch`` (issue 13).

Run:  python benchmarks/bench_scale.py [--repeats N] [--small] [--out FILE]

Whole-process wall time, from starting ``python -m hystkit ...`` to its exit (what a user
waits for: start-up, reading, the work, writing), of

- ``compare`` (10 families, fit on one recording, validate on another), ``generalize`` (10
  families x the four virtual-sensor excitations) and ``select`` (every family's candidates,
  blocked time folds of one recording) at ``--workers 1`` (serial, in-process, no Dask) and
  ``--workers 2`` (a local Dask cluster of two forked workers); issue 13 asks for >= 1.7x on 2
  cores;
- ``compare`` inside one process, split into start-up, opening the executor (Dask import,
  kernel warm-up, cluster start), the map and closing, to see where the time goes;
- a fleet of 20 virtual sensors (different seeds; a fit and a validation recording each)
  through ``hystkit batch`` at 1 and 2 workers, against a shell loop that runs ``hystkit fit``
  and ``hystkit evaluate`` for each sensor (the same work: fit, model file, scores).

Paired and interleaved: every repeat runs each configuration once, the order of the two worker
counts alternating between repeats, so bursts of load hit both alike; reported are the medians
and the median of the per-repeat speed-ups. Wall and CPU time (user + system of the command
and its workers) are both given: on a shared machine the wall time carries the other jobs'
load. ``--small``: 4000-sample recordings, 8 sensors, ``generalize`` on the two recordings,
fewer select candidates (a quick check, not the issue's numbers).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

N_SENSORS = 20

# compare in a fresh process, timed inside: start-up, opening the executor (Dask import, kernel
# warm-up, cluster start), the map itself, closing. Serial map / (2 x parallel map) is the
# efficiency of the 2-worker map; what it lacks is scheduling, transfer and load imbalance.
BREAKDOWN = """
import json, sys, time
t0 = time.perf_counter()
from hystkit.io import read_recording
from hystkit.parallel import open_executor
from hystkit.reports import compare_models
fit, val = read_recording("fit.csv"), read_recording("val.csv")
t1 = time.perf_counter()
with open_executor(int(sys.argv[1])) as executor:
    t2 = time.perf_counter()
    compare_models(fit, val, executor=executor)
    t3 = time.perf_counter()
t4 = time.perf_counter()
print(json.dumps({"start-up": t1 - t0, "open": t2 - t1, "map": t3 - t2, "close": t4 - t3}))
"""


def _machine() -> str:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"platform {platform.platform()}; cpus {os.cpu_count()}; load average {load}\n"
            f"python {platform.python_version()} ({sys.executable})")


def _run(argv: list[str], cwd: Path) -> tuple[float, float]:
    """Wall and CPU time (user + system of the process and the children it waited for)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode not in (0, 3):  # 3: a family or sensor failed its guards, work done
        raise RuntimeError(f"{' '.join(argv)} failed ({proc.returncode}): {proc.stderr}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _recordings(folder: Path, n_samples: int, n_sensors: int) -> None:
    from hystkit.io import Recording, write_recording
    from hystkit.sensors import simulate_experiment

    def head(rec: Recording) -> Recording:
        return Recording(time=rec.time[:n_samples], sensor=rec.sensor[:n_samples],
                         position=rec.position[:n_samples], source=rec.source)

    write_recording(head(simulate_experiment("sine", 1)), folder / "fit.csv")
    write_recording(head(simulate_experiment("sine", 2)), folder / "val.csv")
    lines = ["sensor,fit,validate"]
    for k in range(n_sensors):
        write_recording(head(simulate_experiment("sine", 100 + k)), folder / f"s{k:02d}_fit.csv")
        write_recording(head(simulate_experiment("sine", 200 + k)), folder / f"s{k:02d}_val.csv")
        lines.append(f"s{k:02d},s{k:02d}_fit.csv,s{k:02d}_val.csv")
    (folder / "fleet.csv").write_text("\n".join(lines) + "\n")
    loop = [f"for n in $(seq 0 {n_sensors - 1}); do",
            "  k=$(printf %02d $n)",
            (f"  {sys.executable} -m hystkit fit s${{k}}_fit.csv --out loop/s${{k}}.json --force"
            " > /dev/null || exit 1"),
            (f"  {sys.executable} -m hystkit evaluate loop/s${{k}}.json s${{k}}_val.csv"
            " --json loop/s${k}-scores.json --force > /dev/null || exit 1"),
            "done"]
    (folder / "loop.sh").write_text("\n".join(loop) + "\n")


def _commands(small: bool) -> dict[str, list[str]]:
    hystkit = [sys.executable, "-m", "hystkit"]
    select_models = ["--models", "mpl,pi,bobbio,chua"] if small else []
    return {
        "compare": [*hystkit, "compare", "fit.csv", "val.csv", "--out", "cmp", "--force"],
        # --small: the two recordings (2 x 2 cells a family), else the four excitations
        "generalize": [*hystkit, "generalize", *(["fit.csv", "val.csv"] if small else []),
                       "--out", "gen", "--force"],
        "select": [*hystkit, "select", "fit.csv", *select_models, "--out", "sel.json",
                   "--force"],
        "batch": [*hystkit, "batch", "fleet.csv", "--out", "fleet", "--force"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--small", action="store_true")
    parser.add_argument("--out", type=Path, help="also write the report here")
    args = parser.parse_args()
    n_samples, n_sensors = (4000, 8) if args.small else (8000, N_SENSORS)
    commands = _commands(args.small)
    times: dict[str, list[tuple[float, float]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        (cwd / "loop").mkdir()
        _recordings(cwd, n_samples, n_sensors)
        for repeat in range(args.repeats):
            order = ("1", "2") if repeat % 2 == 0 else ("2", "1")
            times.setdefault("shell loop", []).append(_run(["bash", "loop.sh"], cwd))
            for workers in order:
                parts = json.loads(subprocess.run(
                    [sys.executable, "-c", BREAKDOWN, workers], cwd=cwd, check=True,
                    capture_output=True, text=True).stdout)
                for part, seconds in parts.items():
                    times.setdefault(f"in-process compare {part} @{workers}", []).append(
                        (seconds, 0.0))
            for name, argv in commands.items():
                for workers in order:
                    times.setdefault(f"{name} @{workers}", []).append(
                        _run([*argv, "--workers", workers], cwd))
            print(f"repeat {repeat + 1}/{args.repeats} done", file=sys.stderr, flush=True)
    report = _report(times, commands, args, n_samples, n_sensors)
    print(report)
    if args.out is not None:
        args.out.write_text(report + "\n")


def _report(times: dict, commands: dict, args: argparse.Namespace, n_samples: int,
            n_sensors: int) -> str:
    med = {k: statistics.median(w for w, _ in v) for k, v in times.items()}
    cpu = {k: statistics.median(c for _, c in v) for k, v in times.items()}
    lines = [(f"hystkit scaling (issue 13): whole-process wall time [s], median of "
             f"{args.repeats} interleaved repeats{' (--small)' if args.small else ''}"),
             _machine(), f"recordings of {n_samples} samples; fleet of {n_sensors} sensors", "",
             (f"{'command':<12}{'1 worker':>10}{'2 workers':>11}{'speed-up':>10}"
             f"{'(per-repeat median)':>21}{'CPU 1':>8}{'CPU 2':>8}")]
    for name in commands:
        one, two = times[f"{name} @1"], times[f"{name} @2"]
        ratio = statistics.median(a[0] / b[0] for a, b in zip(one, two))
        lines.append(f"{name:<12}{med[f'{name} @1']:>10.2f}{med[f'{name} @2']:>11.2f}"
                     f"{med[f'{name} @1'] / med[f'{name} @2']:>9.2f}x{ratio:>20.2f}x"
                     f"{cpu[f'{name} @1']:>8.1f}{cpu[f'{name} @2']:>8.1f}")
    lines += ["", "compare in one process [s]: " + "; ".join(
        f"{part} {med[f'in-process compare {part} @1']:.2f} / "
        f"{med[f'in-process compare {part} @2']:.2f}"
        for part in ("start-up", "open", "map", "close")) + " (1 / 2 workers); map efficiency "
        f"{med['in-process compare map @1'] / (2 * med['in-process compare map @2']):.2f}"]
    loop = med["shell loop"]
    lines += ["", (f"{n_sensors} sensors: shell loop of hystkit fit + evaluate {loop:.2f} s "
              f"(CPU {cpu['shell loop']:.1f} s, {loop / n_sensors:.2f} s per sensor); "
              f"hystkit batch {med['batch @1']:.2f} s at 1 worker "
              f"({loop / med['batch @1']:.1f}x faster), {med['batch @2']:.2f} s at 2 "
              f"({loop / med['batch @2']:.1f}x faster)"),
              "all times: " + "; ".join(f"{k} " + ", ".join(f"{w:.2f}" for w, _ in v)
                                        for k, v in times.items()
                                        if not k.startswith("in-process"))]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
