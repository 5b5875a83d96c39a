"""Speed of hystkit's closed-loop simulation: against the loop before the family protocol, with
other families' blocks, and against python-control and a plain Python loop.

Run:  python benchmarks/bench_control.py [--tables loop,command]   (about a minute on 2 cores)

The loop is the document's 5 s closed loop (ch. 7): r = 3 mm sin(pi t) (eq. 7.3), Ts = 5.04e-4 s,
so 9921 steps, plant 1 / (m s^2) (exact ZOH), the eq. 7.2 PID with the document's gains, the
"real" sensor S_r (3-cell mPL fitted on the virtual sensor's noise run) and a compensator fitted
on its sine run (direct mode) -- scheme (a); scheme (b) adds S_m.

Table 1 (protocol cost). ``hystkit`` is today's kernel, one numba specialisation per combination
of the blocks' step functions; ``before`` is the kernel of commit 411a485 (before the family
protocol: mPL and polynomial-mPL blocks hard-wired, ``inline="always"``), rebuilt from git into a
temporary folder and fed the same blocks in its own packing. Both are called with pre-packed
arguments; A and B alternate (A B A B ...) so bursts of load hit both alike; medians of the
repeats and the median of the paired ratios are reported.

Table 3 (whole command). Wall and CPU time (user + system of the child, from ``getrusage``) of a
warm ``hystkit control --scheme direct --experiment sine`` (a fresh process each: interpreter,
imports, sensor models and margins from the disk cache, loop kernel from numba's cache, the run,
metrics and figure written), this tree (or ``--src DIR``) against ``--reference`` (default
``REFERENCE``; extracted with ``git archive`` into a temporary folder and run with
``PYTHONPATH``); one untimed run of each first fills the caches (numba's, and the sensor models
and margins in a temporary ``HYSTKIT_CACHE_DIR`` shared by both: its keys name the code), then
``COMMAND_REPEATS`` pairs A B A B, medians and the medians of the paired ratios. CPU is quoted
beside wall because the machine is shared: wall moves with the load, CPU far less.

Table 2 (families and references). ``simulate_loop`` with a 3-cell mPL, a 10-operator PI and a
20-level Preisach compensator (S_r stays the mPL; ``first call`` includes compiling the loop for
that combination of blocks, 0 when table 1 compiled it already); ``Python``: ``simulate_loop_reference``, the
readable loop over block steps; ``python-control``: ``control.input_output_response`` on
``hystkit.control.loop_nlsys(loop)`` with the mPL loop. Every variant's plant position is compared
with hystkit's (max |y difference|, metres) to show they do the same work.
"""

from __future__ import annotations

import argparse
import importlib
import io
import os
import platform
import resource
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # small fits, no threads

import control
import numba
import numpy as np

import hystkit
from hystkit import control as hc
from hystkit.compensation import fit_compensator
from hystkit.control import _kernel
from hystkit.models import mpl
from hystkit.sensors import simulate_experiment

SECONDS = 5.0
REPEATS = 21
PY_REPEATS = 3
BEFORE = "411a485"  # the last commit before the family protocol
REFERENCE = "7ec2408"  # before pandas left the loop run (issue 29.3); 2bff934: before the disk cache
COMMAND = ["control", "--scheme", "direct", "--experiment", "sine"]
COMMAND_REPEATS = 9
REPO = Path(__file__).resolve().parents[1]


def machine() -> None:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print("Machine")
    print(f"  platform     {platform.platform()}; cpus {os.cpu_count()} "
          f"(usable {len(os.sched_getaffinity(0))})")
    print(f"  load average {load} (1, 5, 15 min) at start")
    print(f"  python       {platform.python_version()}; numpy {np.__version__}, numba "
          f"{numba.__version__}, python-control {control.__version__}, hystkit "
          f"{hystkit.__version__}")
    print()


def old_kernel(folder: Path):
    """The pre-protocol loop kernel as a stand-alone package ``before_protocol`` in ``folder``."""
    pkg = folder / "before_protocol"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    for name in ("_mpl_kernels", "_mpl_poly_kernels"):
        text = subprocess.run(["git", "show", f"{BEFORE}:src/hystkit/models/{name}.py"],
                              cwd=REPO, check=True, capture_output=True, text=True).stdout
        (pkg / f"{name}.py").write_text(text)
    text = subprocess.run(["git", "show", f"{BEFORE}:src/hystkit/control/_kernel.py"], cwd=REPO,
                          check=True, capture_output=True, text=True).stdout
    text = (text.replace("from ..models._mpl_kernels", "from ._mpl_kernels")
            .replace("from ..models._mpl_poly_kernels", "from ._mpl_poly_kernels")
            .replace("from ._sensors import BLOCK_HEADER", "BLOCK_HEADER = 10"))
    (pkg / "_kernel.py").write_text(text)
    sys.path.insert(0, str(folder))
    return importlib.import_module("before_protocol._kernel")


def old_pack(block: hc.SensorBlock, dt: float) -> np.ndarray:
    """An mPL block in the pre-protocol layout: header of 10, then i_s, v_t, knee, w."""
    s, p = block.at(dt), block.params
    header = [p.n_cells, float(block.inverse), p.v_b, s.slope_cap / dt, dt,
              1.0 / block.in_scale, -block.in_offset / block.in_scale, block.out_scale,
              block.out_offset, 0.0]
    return np.concatenate([header, p.i_s, p.v_t, mpl.knee_voltage(s, p), p.w])


def protocol_cost(models: hc.SensorModels, r: np.ndarray, old) -> list[tuple]:
    rows = []
    zeros = np.zeros(r.size)
    for scheme in hc.SCHEMES:
        loop = hc.build_loop(scheme, models)
        x0 = hc.rest_state(loop, float(r[0])).to_vector()
        args = loop.kernel_arguments()
        direct, plant, pid, dob, y_limit = args[:5]
        blocks = [old_pack(b, loop.ts) if b is not None else np.empty(0)
                  for b in (loop.sensor, loop.compensator, loop.model)]

        def new(args=args, x0=x0):
            return _kernel.run(r, zeros, zeros, zeros, x0, *args)

        def before(x0=x0, plant=plant, pid=pid, dob=dob, direct=direct, y_limit=y_limit,
                   blocks=blocks):
            return old.run(r, zeros, zeros, zeros, x0, direct, plant, pid, dob, y_limit,
                           *blocks)

        diff = float(np.max(np.abs(new()[0][0] - before()[0][0])))
        times = {"hystkit": [], "before": []}
        for _ in range(REPEATS):
            for name, fn in (("hystkit", new), ("before", before)):
                t0 = time.perf_counter()
                fn()
                times[name].append(time.perf_counter() - t0)
        ratios = [a / b for a, b in zip(times["hystkit"], times["before"], strict=True)]
        rows.append((scheme, statistics.median(times["before"]),
                     statistics.median(times["hystkit"]), statistics.median(ratios), diff))
    return rows


def family_rows(r: np.ndarray, models: hc.SensorModels) -> list[tuple]:
    rows = []
    sine = simulate_experiment("sine", 2)
    for family, size in (("mpl", 3), ("pi", 10), ("preisach", 20)):
        comp = fit_compensator(sine, size, model=family, mode="direct", center="fit")
        loop = hc.build_loop("direct", hc.SensorModels(
            models.sensor, hc.compensator_block(comp), models.model, models.sensor_gain))
        t0 = time.perf_counter()
        fast = hc.simulate_loop(loop, r[:10])
        t_compile = time.perf_counter() - t0
        fast = hc.simulate_loop(loop, r)
        times = []
        for _ in range(REPEATS):
            t0 = time.perf_counter()
            hc.simulate_loop(loop, r)
            times.append(time.perf_counter() - t0)
        t_fast = statistics.median(times)
        rows.append((family, "hystkit", t_fast, 0.0, 1.0, t_compile))
        slow_times = []
        for _ in range(PY_REPEATS):
            t0 = time.perf_counter()
            slow = hc.simulate_loop_reference(loop, r)
            slow_times.append(time.perf_counter() - t0)
        t_slow = statistics.median(slow_times)
        rows.append((family, "Python", t_slow, float(np.max(np.abs(slow.y - fast.y))),
                     t_slow / t_fast, None))
        if family == "mpl":
            sys_ = hc.loop_nlsys(loop)
            x0 = hc.loop_initial_state(loop, r0=float(r[0]))
            zeros = np.zeros(r.size)
            t0 = time.perf_counter()
            pc = control.input_output_response(sys_, np.arange(r.size) * hc.TS,
                                               [r, zeros, zeros], x0)
            t_pc = time.perf_counter() - t0
            rows.append((family, "python-control", t_pc,
                         float(np.max(np.abs(pc.outputs[0] - fast.y))), t_pc / t_fast, None))
    return rows


def reference_source(folder: Path, reference: str) -> Path:
    """`reference`'s ``src`` extracted into `folder` (a checkout shared with others stays
    untouched)."""
    archive = subprocess.run(["git", "archive", reference, "src"], cwd=REPO, check=True,
                             capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
        tar.extractall(folder, filter="data")
    return folder / "src"


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def whole_command(folder: Path, src: Path, reference: str) -> dict[str, tuple[float, float]]:
    """Medians of the warm command's wall and CPU time [s]: ``hystkit`` (the tree `src`),
    ``before`` (`reference`) and ``ratio`` (the medians of the paired ratios)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "OPENBLAS_NUM_THREADS")}
    env["HYSTKIT_CACHE_DIR"] = str(folder / "cache")
    variants = {"hystkit": {**env, "PYTHONPATH": str(src)},
                "before": {**env, "PYTHONPATH": str(reference_source(folder / "ref", reference))}}
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in variants}
    for k in range(COMMAND_REPEATS + 1):
        for name, variant_env in variants.items():
            out = folder / f"run-{name}-{k}"
            t0, c0 = time.perf_counter(), _children_cpu()
            subprocess.run([sys.executable, "-m", "hystkit", *COMMAND, "--out", str(out)],
                           env=variant_env, cwd=folder, check=True, capture_output=True)
            if k:  # the first pair fills the caches
                times[name].append((time.perf_counter() - t0, _children_cpu() - c0))
    medians = {name: tuple(statistics.median(run[i] for run in runs) for i in (0, 1))
               for name, runs in times.items()}
    medians["ratio"] = tuple(statistics.median(a[i] / b[i] for a, b in
                                               zip(times["hystkit"], times["before"], strict=True))
                             for i in (0, 1))
    return medians


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tables", default="loop,command",
                        help="loop (tables 1 and 2), command (table 3), or both (default)")
    parser.add_argument("--src", type=Path, default=REPO / "src",
                        help="source tree of table 3's hystkit (default: this checkout's)")
    parser.add_argument("--reference", default=REFERENCE,
                        help=f"git revision table 3 pairs it with (default {REFERENCE})")
    args = parser.parse_args()
    tables = args.tables.split(",")
    t_total = time.perf_counter()
    machine()
    if "loop" in tables:
        loop_tables()
    if "command" in tables:
        with tempfile.TemporaryDirectory() as folder:
            medians = whole_command(Path(folder), args.src, args.reference)
        load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
        print(f"Table 3. whole command, warm: hystkit {' '.join(COMMAND)}; medians of "
              f"{COMMAND_REPEATS} A/B pairs of fresh processes (load {load} at the end)")
        print(f"  {'':<6}{'before (' + args.reference + ') s':>20}{'hystkit s':>11}"
              f"{'ratio (median of pairs)':>25}")
        for i, what in enumerate(("wall", "cpu")):
            print(f"  {what:<6}{medians['before'][i]:>20.3f}{medians['hystkit'][i]:>11.3f}"
                  f"{medians['ratio'][i]:>25.3f}")
        print()
    print(f"Total benchmark time {time.perf_counter() - t_total:.1f} s")


def loop_tables() -> None:
    t0 = time.perf_counter()
    models = hc.fit_sensor_models()
    t_fit = time.perf_counter() - t0
    n = round(SECONDS / hc.TS)
    r = hc.sine_reference(n)
    with tempfile.TemporaryDirectory() as folder:
        old = old_kernel(Path(folder))
        t0 = time.perf_counter()
        proto = protocol_cost(models, r, old)
        t_proto = time.perf_counter() - t0
    fam = family_rows(r, models)
    print(f"One-off: fit_sensor_models (3 cells each) {t_fit:.2f} s; table 1 incl. compiles "
          f"{t_proto:.1f} s")
    print()
    print(f"Table 1. {SECONDS:g} s loop, {n} steps, mPL blocks (3 cells): kernel before the "
          f"protocol ({BEFORE}) vs today's; medians of {REPEATS} A/B pairs")
    print(f"  {'scheme':<10}{'before ms':>11}{'hystkit ms':>12}{'ratio (median of pairs)':>25}"
          f"{'max|y diff| m':>15}")
    for scheme, t_old, t_new, ratio, diff in proto:
        print(f"  {scheme:<10}{t_old * 1e3:>11.2f}{t_new * 1e3:>12.2f}{ratio:>25.3f}"
              f"{diff:>15.1e}")
    print()
    print(f"Table 2. scheme (a), S_r 3-cell mPL, compensator of each family; hystkit: median of "
          f"{REPEATS}, Python: median of {PY_REPEATS}, python-control: 1 run")
    print(f"  {'compensator':<13}{'variant':<16}{'ms / run':>11}{'us / step':>11}"
          f"{'x hystkit':>11}{'max|y diff| m':>15}{'first call s':>14}")
    for family, name, seconds, diff, ratio, compile_s in fam:
        c = f"{compile_s:.2f}" if compile_s is not None else ""
        print(f"  {family:<13}{name:<16}{seconds * 1e3:>11.2f}{seconds / n * 1e6:>11.3f}"
              f"{ratio:>11.1f}{diff:>15.1e}{c:>14}")
    print()


if __name__ == "__main__":
    main()
