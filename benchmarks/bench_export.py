"""Footprint and speed of the exported compensators, beside the Python stream.

Run:  python benchmarks/bench_export.py [--quick]     (writes benchmarks/last_run_export.txt)

Compensators are fitted (direct mode, centring fit) on the virtual sensor's sine run, as in
``bench_stream.py``, and exported with ``hystkit.export``. Per family:

- ``state B``: ``sizeof(NAME_state)`` in float / double (model state, centring, flags);
- ``step B``: size of the compiled ``NAME_step`` symbol (``nm -S``; the family's model code is
  inlined into it) and ``.text`` of the whole object (``size``; init, sync and step), float,
  ``cc -O2 -std=c99``, this machine (x86-64; a Cortex-M build is smaller or larger by the ISA);
- ``C ns``: nanoseconds per sample, float / double: ``NAME_step`` over 1e6 samples (the decay
  run's 8000 sensor samples 125 times, the state carried on), median of interleaved repeats
  (every repeat runs every family once, so load bursts hit all alike);
- ``octave µs``: the MATLAB export in GNU Octave, ``NAME(sensor)`` on 2000 samples, per sample;
- Python rows from ``bench_stream.python_latency``: ``Stream.step``, ``Stream.process`` on
  chunks of 64, and the family's readable ``step`` in a plain-Python loop (µs per sample).
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from hystkit.compensation import fit_compensator
from hystkit.export import c_files, make_plan, matlab_files
from hystkit.sensors import simulate_experiment

sys.path.insert(0, str(Path(__file__).parent))
from bench_stream import FAMILIES, python_latency

HERE = Path(__file__).parent
N_LOOP = 1_000_000

_TIMER = r"""#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "comp.h"
#define N_MAX 8000
static comp_real data[N_MAX];
int main(int argc, char **argv)
{
    FILE *f = fopen(argv[1], "r");
    long n = 0, k, total = atol(argv[2]);
    double v, check = 0.0;
    comp_state st;
    struct timespec t0, t1;
    (void)argc;
    while (n < N_MAX && fscanf(f, "%lf", &v) == 1) data[n++] = (comp_real)v;
    fclose(f);
    comp_init(&st, data[0]);
    for (k = 0; k < n; k++) check += comp_step(&st, data[k]);  /* warm the caches */
    comp_init(&st, data[0]);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (k = 0; k < total; k++) check += comp_step(&st, data[k % n]);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("%zu %.3f %g\n", sizeof(comp_state),
           ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / total, check);
    return 0;
}
"""


def _build(comp, folder: Path, double: bool) -> dict:
    folder.mkdir(parents=True)
    for name, text in c_files(make_plan(comp, "comp"), double).items():
        if name != "example_main.c":
            (folder / name).write_text(text)
    (folder / "timer.c").write_text(_TIMER)
    cc = ["cc", "-O2", "-std=c99"]
    subprocess.run([*cc, "-c", "comp.c"], cwd=folder, check=True)
    subprocess.run([*cc, "comp.c", "timer.c", "-lm", "-o", "timer"], cwd=folder, check=True)
    text = int(subprocess.run(["size", "comp.o"], cwd=folder, check=True, capture_output=True,
                              text=True).stdout.splitlines()[1].split()[0])
    step = 0
    for line in subprocess.run(["nm", "-S", "comp.o"], cwd=folder, check=True,
                               capture_output=True, text=True).stdout.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[3] == "comp_step":
            step = int(parts[1], 16)
    return {"timer": folder / "timer", "text": text, "step": step}


def _time(binary: Path, data: Path, n: int) -> tuple[int, float]:
    out = subprocess.run([str(binary), str(data), str(n)], check=True, capture_output=True,
                         text=True).stdout.split()
    return int(out[0]), float(out[1])


def _octave_us(comp, folder: Path, data: Path, n: int) -> float | None:
    if shutil.which("octave") is None:
        return None
    folder.mkdir(parents=True)
    for name, text in matlab_files(make_plan(comp, "comp")).items():
        (folder / name).write_text(text)
    script = (f"cd('{folder}'); s = load('{data}'); s = s(1:{n}); comp(s(1:10)); tic; "
              f"comp(s); printf('%.6f\\n', toc / {n});")
    out = subprocess.run(["octave", "--no-gui", "--quiet", "--eval", script], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[-1]) * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer samples and repeats")
    args = parser.parse_args()
    repeats, n_loop, n_python = (3, N_LOOP // 10, 500) if args.quick else (7, N_LOOP, 2000)
    fit_rec, use_rec = simulate_experiment("sine", 1), simulate_experiment("decay", 2)
    lines = [(f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load "
              f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}; C: cc -O2 -std=c99, "
              f"{n_loop} samples x {repeats} interleaved repeats (median); Octave: "
              f"{n_python} samples; Python: bench_stream.python_latency, {n_python} samples")]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        data = tmp / "sensor.txt"
        np.savetxt(data, use_rec.sensor, fmt="%.17g")
        comps, builds = {}, {}
        for name, size in FAMILIES:
            label = f"{name} {size}"
            comps[label] = fit_compensator(fit_rec, size, model=name, diagnose=False)
            for double in (False, True):
                builds[label, double] = _build(comps[label], tmp / f"{name}-{size}-{double}",
                                               double)
        ns = {key: [] for key in builds}
        state = {}
        for _ in range(repeats):
            for key, build in builds.items():
                state[key], t = _time(build["timer"], data, n_loop)
                ns[key].append(t)
        header = (f"{'model':<12} {'state B f/d':>12} {'step B':>7} {'.text B':>8} "
                  f"{'C ns f/d':>13} {'octave µs':>10} {'step µs':>8} {'proc/64 µs':>10} "
                  f"{'py loop µs':>10}")
        lines.append(header)
        print("\n".join(lines), flush=True)
        for label, comp in comps.items():
            f32 = builds[label, False]
            octave = _octave_us(comp, tmp / f"m-{label.replace(' ', '-')}", data, n_python)
            py = python_latency(comp, use_rec.sensor[:n_python], repeats=max(3, repeats // 2))
            row = (f"{label:<12} {state[label, False]:>5} / {state[label, True]:<5} "
                   f"{f32['step']:>7} {f32['text']:>8} "
                   f"{statistics.median(ns[label, False]):>6.0f} / "
                   f"{statistics.median(ns[label, True]):<5.0f} "
                   f"{'-' if octave is None else f'{octave:.0f}':>10} {py['step_us']:>8.1f} "
                   f"{py['process_chunk_us']:>10.2f} {py['python_loop_us']:>10.1f}")
            lines.append(row)
            print(row, flush=True)
    lines.append(f"# load at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(lines[-1])
    (HERE / "last_run_export.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
