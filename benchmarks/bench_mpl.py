"""Speed of hystkit's mPL forward model and of its fit, against references run in the same process.

Run:  python benchmarks/bench_mpl.py [--fit-only] [--quick] [--pair DIR [--rounds K]]
      (several minutes on 2 cores: the 128k-sample trf fits take up to a minute each;
      --fit-only skips table 1 and the compile costs; --quick keeps only N = 1 of the
      128k-sample rows, for a loaded machine; --pair: see below)

Table 1 -- forward model cost in ns per sample per cell, for N = 1, 3, 10 cells on a
100 000-sample normalised input (0.5 Hz sine plus white noise, max |u| = 1, dt = 0.025 s):

* ``hystkit.models.mpl.simulate``: the numba kernel plus its Python wrapper (checks, knee),
* the bare numba kernel ``hystkit.models.mpl.kernels.simulate`` (to show what the wrapper costs),
* ``_c_reference.c``: the same loop in C, compiled now with ``cc -O2 -shared -fPIC`` (no
  -ffast-math) and called through ctypes; its output must match hystkit's to ~1e-12,
* ``simulate_reference``: the plain Python loop over ``step``, on 2 000 samples.

Each figure is the *minimum* over 15 repeats of ``time.perf_counter`` around one call, after a
warm-up call, with the variants interleaved within each repeat; the minimum is the least disturbed estimate of the cost of the work. The
numba compile (or cache load) and the C compile are one-off costs, reported separately.

Table 2 -- wall time of ``fit_mpl`` in *simulations' worth*: fit wall time divided by one
compiled ``mpl.simulate`` of the same data with the same cell count, both measured in the same
run (the ratio cancels most of the machine's speed and load). N = 1, 3, 5 cells on the virtual
sensor's sine fitting recording (8000 samples, seed 1 as in the demo report) and on 16 such
recordings (seeds 1-16) joined into 128 000 samples, direct mode (input = normalised sensor,
output = normalised position). Each row compares the default solver (``solver="tr"``: scipy's
trust-region reflective on one-pass normal equations) with the previous one (``solver="trf"``:
``scipy.optimize.least_squares`` on the dense exact Jacobian), interleaved A B A B, with the
medians, their ratio and both final SSEs. Reference for N = 1: ``least_squares`` with a
finite-difference ('2-point') Jacobian from the same first start.
The same fits are also given in simulations' worth of the fast C reference
(``_c_fast_reference.c``'s ``mpl_fast`` at ``-O3 -march=native``, built by ``_c_build.py`` as
``bench_kernels.py`` builds it), timed interleaved with every ``mpl.simulate`` call (issue 29.5).

Paired mode (``--pair DIR``, DIR another checkout, e.g. a ``git worktree`` of the commit to
compare against): only the default solver's fits at 8000 samples (1, 3, 5 cells), each round
run in a fresh process of DIR/src and then of this checkout's src (A B A B, ``--rounds`` pairs,
3 by default), every process timing its own fast C reference after each fit; printed are the
model runs and SSE of each side, the median fit cost in fast-C simulations by CPU time and the
paired ratios (after / before, each round's pair) with their median and range.

BLAS: unless OPENBLAS_NUM_THREADS is already set, this script sets it to 1 before numpy loads.
The trf path's linear algebra (scipy's SVD in least_squares) is on n x <= 17 matrices, too small
for threads to pay; on a 2-core machine with another process busy, OpenBLAS's two spinning
threads made the same fit 10-30x slower and erratic (N = 3: 8-28 s instead of 0.8 s), while on
an idle machine 1 and 2 threads timed alike. Export OPENBLAS_NUM_THREADS to measure another
setting.
"""

from __future__ import annotations

import ctypes
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__":
    # Must precede the first numpy import to take effect (see the module docstring).
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numba
import numpy as np
import scipy
from _c_build import FAST_FLAGS, SLOW_FLAGS, SLOW_SOURCE, fast_mpl
from scipy.optimize import least_squares

import hystkit
from hystkit.compensation import centre_and_scale
from hystkit.models import mpl
from hystkit.models.mpl import default_starts, fit_mpl, kernels
from hystkit.models.mpl import fit as _fit
from hystkit.sensors._virtual import simulate_experiment

DT = 0.025
SIM_CELLS = (1, 3, 10)
SIM_SAMPLES = 100_000
SIM_REPEATS = 15
PY_SAMPLES = 2_000
FIT_CELLS = (1, 3, 5)
FIT_SIZES = (8000, 128_000)  # samples: one recording, 16 recordings joined
FIT_REPEATS = {8000: 3, 128_000: 2}  # interleaved pairs (tr, trf) per row
SIM_TIMING_REPEATS = 7
FIT_ONLY = "--fit-only" in sys.argv
QUICK = "--quick" in sys.argv
PAIR_WORKER = "--pair-worker" in sys.argv  # one side of one round of --pair (internal)


def _option(name: str, default: str | None = None) -> str | None:
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


PAIR = _option("--pair")
ROUNDS = int(_option("--rounds", "3"))
FIT_SEED = 1  # the demo report's fitting seed (hystkit.studies._demo.FIT_SEED)
C_FLAGS = SLOW_FLAGS
C_SOURCE = SLOW_SOURCE


# ----------------------------------------------------------------------------- machine

def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def compiler_version(cc: str | None) -> str:
    if cc is None:
        return "none found"
    out = subprocess.run([cc, "--version"], capture_output=True, text=True, check=False)
    return out.stdout.splitlines()[0] if out.stdout else cc


def print_machine(cc: str | None) -> None:
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    # Load average matters: other jobs on a 2-core box shift every number below.
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "n/a"
    print("Machine")
    print(f"  platform     {platform.platform()}")
    print(f"  CPU          {cpu_model()}; os.cpu_count() = {os.cpu_count()}, usable = {usable}")
    print(f"  load average {load} (1, 5, 15 min) at start")
    print(f"  python       {platform.python_version()}; numpy {np.__version__}, "
          f"numba {numba.__version__}, scipy {scipy.__version__}, "
          f"hystkit {getattr(hystkit, '__version__', '?')}")
    print(f"  C compiler   {compiler_version(cc)}")
    print(f"  OPENBLAS_NUM_THREADS = {os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}")
    print()


# ----------------------------------------------------------------------------- timing

def interleaved_min(fns: dict, repeats: int) -> dict:
    """Minimum seconds of one call of each ``fns[name]()`` over ``repeats`` rounds.

    One untimed warm-up call each, then the variants take turns within every round, so a burst
    of load from other processes hits all of them alike instead of skewing one column.
    """
    for fn in fns.values():
        fn()
    best = dict.fromkeys(fns, float("inf"))
    for _ in range(repeats):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            best[name] = min(best[name], time.perf_counter() - t0)
    return best


def first_call_seconds(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


# ----------------------------------------------------------------------------- inputs

def sim_input(n: int, seed: int = 0) -> np.ndarray:
    """Normalised 0.5 Hz sine plus white noise, centred, max |u| = 1.

    The noise gives sample-to-sample jumps large enough to push some cells past their knee,
    so the linear continuation branch runs too, not only the sinh branch.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(n) * DT
    u = np.sin(2 * np.pi * 0.5 * t) + 0.3 * rng.standard_normal(n)
    u -= u.mean()
    return u / np.max(np.abs(u))


def sim_model(n_cells: int) -> tuple[mpl.MplStructure, mpl.MplParams]:
    """i_s = 0.05, V_T spread 0.1 .. 0.3, all weights 0.5, V_b = 0.1.

    V_T ~ 0.1 puts the knee at |v| ~ 0.44, reachable by the input's jumps; at V_T = 0.3 the
    knee is at 1.64 and a normalised input would never leave the sinh region.
    """
    structure = mpl.MplStructure(n_cells=n_cells, dt=DT)
    params = mpl.MplParams(i_s=np.full(n_cells, 0.05), v_t=np.geomspace(0.1, 0.3, n_cells),
                           w=np.full(n_cells + 1, 0.5), v_b=0.1)
    return structure, params


def linear_branch_share(structure: mpl.MplStructure, params: mpl.MplParams,
                        u: np.ndarray) -> float:
    """Share of cell-samples that took the straight-line branch (|u - x_k| > knee_k).

    Cells evolve independently given the input, so each cell's state trajectory is the output
    of a one-cell model with w = [0, 1] and no bias.
    """
    knee = mpl.knee_voltage(structure, params)
    one = mpl.MplStructure(n_cells=1, dt=structure.dt, slope_cap=structure.slope_cap)
    hits = 0
    for k in range(structure.n_cells):
        cell = mpl.MplParams(i_s=params.i_s[k:k + 1], v_t=params.v_t[k:k + 1], w=[0.0, 1.0])
        x, _ = mpl.simulate(one, cell, u)
        hits += int(np.count_nonzero(np.abs(u - x) > knee[k]))
    return hits / (u.size * structure.n_cells)


# ----------------------------------------------------------------------------- C reference

def build_c_reference(cc: str, workdir: str):
    """Compile ``_c_reference.c`` into ``workdir``; return (ctypes function, compile seconds)."""
    lib_path = Path(workdir) / "mpl_c_reference.so"
    t0 = time.perf_counter()
    subprocess.run([cc, *C_FLAGS, "-o", str(lib_path), str(C_SOURCE), "-lm"], check=True)
    seconds = time.perf_counter() - t0
    func = ctypes.CDLL(str(lib_path)).mpl_simulate
    arr = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
    func.argtypes = [arr, ctypes.c_int64, arr, ctypes.c_int64, arr, arr, arr, ctypes.c_double,
                     arr, ctypes.c_double, ctypes.c_double, arr]
    func.restype = None
    return func, seconds


def c_simulate(func, u: np.ndarray, x0: np.ndarray, i_s, v_t, w, v_b, knee, cap,
               dt) -> tuple[np.ndarray, np.ndarray]:
    """Same signature and allocations as the numba kernel (copies x0, allocates y)."""
    x = x0.copy()
    y = np.empty(u.size)
    func(u, u.size, x, x.size, i_s, v_t, w, v_b, knee, cap, dt, y)
    return y, x


def kernel_args(structure: mpl.MplStructure, params: mpl.MplParams, u: np.ndarray) -> tuple:
    """Arguments of ``hystkit.models.mpl.kernels.simulate`` exactly as ``mpl.simulate`` builds them."""
    return (u, np.full(structure.n_cells, u[0]), params.i_s, params.v_t, params.w, params.v_b,
            mpl.knee_voltage(structure, params), structure.slope_cap / structure.dt,
            structure.dt)


# ----------------------------------------------------------------------------- compile costs

def numba_compile_seconds(dispatcher, args: tuple) -> tuple[float, float, str]:
    """(first call of the package's dispatcher, cold compile of an uncached copy, cache note).

    With ``cache=True`` the first call in a process usually loads machine code from
    ``__pycache__``; compiling a fresh copy of the same Python function shows what a cold
    cache (first install, changed source) costs.
    """
    first = first_call_seconds(lambda: dispatcher(*args))
    stats = dispatcher.stats
    note = ("loaded from numba's on-disk cache" if sum(stats.cache_hits.values())
            else "compiled (cache miss)")
    fresh = numba.njit(dispatcher.py_func)
    cold = first_call_seconds(lambda: fresh(*args))
    return first, cold, note


def print_compile_costs(c_seconds: float | None) -> None:
    structure, params = sim_model(1)
    u = sim_input(1000)
    sim = numba_compile_seconds(kernels.simulate, kernel_args(structure, params, u))
    jac = numba_compile_seconds(kernels.simulate_with_jacobian, kernel_args(structure, params, u))
    args = kernel_args(structure, params, u)
    normal = numba_compile_seconds(kernels.normal_equations, (u, u, *args[1:]))
    print("One-off costs (not included in the tables)")
    for name, (first, cold, note) in (("simulate", sim), ("simulate_with_jacobian", jac),
                                      ("normal_equations", normal)):
        print(f"  numba {name:<23} first call {first * 1e3:8.1f} ms ({note}); "
              f"cold compile {cold * 1e3:8.1f} ms")
    if c_seconds is not None:
        print(f"  C reference: cc {' '.join(C_FLAGS)}        {c_seconds * 1e3:8.1f} ms")
    print()


# ----------------------------------------------------------------------------- table 1

def simulation_row(n_cells: int, c_func) -> dict:
    structure, params = sim_model(n_cells)
    u = sim_input(SIM_SAMPLES)
    u_py = u[:PY_SAMPLES].copy()
    args = kernel_args(structure, params, u)
    per = 1e9 / (SIM_SAMPLES * n_cells)  # seconds per call -> ns per sample per cell

    fns = {"hystkit": lambda: mpl.simulate(structure, params, u),
           "kernel": lambda: kernels.simulate(*args),
           "python": lambda: mpl.simulate_reference(structure, params, u_py)}
    if c_func is not None:
        fns["c"] = lambda: c_simulate(c_func, *args)
    best = interleaved_min(fns, SIM_REPEATS)
    row = {name: seconds * per for name, seconds in best.items()}
    row["python"] = best["python"] * 1e9 / (PY_SAMPLES * n_cells)  # shorter input
    row.update(n=n_cells, linear=linear_branch_share(structure, params, u))
    if c_func is not None:
        y_hk, x_hk = mpl.simulate(structure, params, u)
        y_c, x_c = c_simulate(c_func, *args)
        row["diff"] = max(float(np.max(np.abs(y_c - y_hk))), float(np.max(np.abs(x_c - x_hk))))
    return row


def print_simulation_table(c_func, cc: str | None) -> None:
    rows = [simulation_row(n, c_func) for n in SIM_CELLS]
    print(f"Table 1. mPL forward model, ns per sample per cell (min of {SIM_REPEATS} interleaved "
          f"repeats after warm-up; {SIM_SAMPLES} samples, Python: {PY_SAMPLES} samples)")
    if c_func is None:
        print("  no C compiler found (cc, gcc, clang, $CC): C column skipped")
    else:
        print(f"  C = _c_reference.c, {Path(cc).name} {' '.join(C_FLAGS)} (no -ffast-math), "
              f"via ctypes; max|diff| = max abs difference of C vs hystkit output and end state")
    print("  linear % = share of cell-samples on the straight-line continuation beyond the knee")
    head = (f"  {'N':>3} {'hystkit':>9} {'kernel':>9} {'C -O2':>9} {'Python':>10} "
            f"{'hk / C':>8} {'Py / hk':>8} {'max|diff|':>10} {'linear %':>9}")
    print(head)
    print("  " + "-" * (len(head) - 2))
    for r in rows:
        c = f"{r['c']:9.2f}" if "c" in r else f"{'-':>9}"
        ratio = f"{r['hystkit'] / r['c']:8.2f}" if "c" in r else f"{'-':>8}"
        diff = f"{r['diff']:10.1e}" if "diff" in r else f"{'-':>10}"
        print(f"  {r['n']:>3} {r['hystkit']:9.2f} {r['kernel']:9.2f} {c} {r['python']:10.0f} "
              f"{ratio} {r['python'] / r['hystkit']:8.0f} {diff} {100 * r['linear']:9.2f}")
    print("  hystkit = mpl.simulate (wrapper + numba kernel); kernel = mpl.kernels.simulate "
          "alone")
    print()


# ----------------------------------------------------------------------------- table 2

def fit_data(n_samples: int = 8000) -> tuple[np.ndarray, np.ndarray, float]:
    """Direct mode: input = normalised sensor, output = normalised position (eq. 5.10).

    8000 samples: the seed-1 sine recording; more: recordings of seeds 1, 2, ... joined (each
    normalised on its own, as a user would fit several recordings).
    """
    parts, dt = [], None
    for seed in range(FIT_SEED, FIT_SEED + max(1, n_samples // 8000)):
        rec = simulate_experiment("sine", seed)
        _, s, p = centre_and_scale(rec, "recording")
        parts.append((s, p))
        dt = rec.dt
    u = np.concatenate([s for s, _ in parts])[:n_samples]
    y = np.concatenate([p for _, p in parts])[:n_samples]
    return np.ascontiguousarray(u), np.ascontiguousarray(y), dt


def fit_bounds(structure: mpl.MplStructure) -> tuple[np.ndarray, np.ndarray]:
    """The bounds ``fit_mpl`` builds internally (optimiser coordinates of MplParams)."""
    return _fit.fit_box(structure)


def fd_reference_fit(u: np.ndarray, y: np.ndarray, structure: mpl.MplStructure) -> dict:
    """least_squares('2-point') from fit_mpl's first start; residuals from mpl.simulate.

    Same solver options as fit_mpl (trf, x_scale='jac', same bounds and theta0) except the
    Jacobian and the budget (scipy's default); only one start, run to convergence.
    """
    lower, upper = fit_bounds(structure)
    i_s, v_t = default_starts(structure)[0]
    theta0 = np.clip(_fit._linear_init(structure, np.asarray(i_s, float),
                                       np.asarray(v_t, float), u, y).to_vector(),
                     lower + 1e-9, upper - 1e-9)
    calls = [0]

    def residuals(theta: np.ndarray) -> np.ndarray:
        calls[0] += 1
        params = mpl.MplParams.from_vector(theta, structure.n_cells)
        return mpl.simulate(structure, params, u)[0] - y

    t0 = time.perf_counter()
    sol = least_squares(residuals, theta0, jac="2-point", bounds=(lower, upper), method="trf",
                        x_scale="jac")
    return {"seconds": time.perf_counter() - t0, "cost": 2.0 * float(sol.cost),
            "runs": calls[0], "converged": sol.status > 0}


def hystkit_fit(u: np.ndarray, y: np.ndarray, structure: mpl.MplStructure,
                starts=None, solver: str = "tr") -> dict:
    t0, c0 = time.perf_counter(), time.process_time()
    res = fit_mpl(u, y, structure, starts=starts, solver=solver)
    return {"seconds": time.perf_counter() - t0, "cpu": time.process_time() - c0,
            "cost": res.cost, "runs": res.n_evaluations, "converged": res.converged,
            "params": res.params}


def repeated(fn, repeats: int) -> dict:
    """Median wall time of ``repeats`` runs (plus min and max); cost etc. of the last run."""
    runs = [fn() for _ in range(repeats)]
    return summarise(runs)


def summarise(runs: list[dict]) -> dict:
    times = [r["seconds"] for r in runs]
    out = {**runs[-1], "seconds": statistics.median(times), "min": min(times),
           "max": max(times)}
    if "cpu" in runs[-1]:
        out["cpu"] = statistics.median(r["cpu"] for r in runs)
    return out


def simulate_seconds(structure: mpl.MplStructure, params: mpl.MplParams, u: np.ndarray,
                     fast_c=None) -> dict[str, list[tuple[float, float]]]:
    """(wall, CPU) seconds of ``SIM_TIMING_REPEATS`` compiled ``mpl.simulate`` calls (wrapper
    included) over ``u``, after one untimed call: ``{"sim": [...]}``; with ``fast_c`` (the fast
    C reference's ``mpl_fast``) also ``"fast"``, the same run in it, interleaved A B A B."""
    args = kernel_args(structure, params, u)
    calls = {"sim": lambda: mpl.simulate(structure, params, u)}
    if fast_c is not None:
        calls["fast"] = lambda: c_simulate(fast_c, *args)
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in calls}
    for call in calls.values():
        call()
    for _ in range(SIM_TIMING_REPEATS):
        for name, call in calls.items():
            t0, c0 = time.perf_counter(), time.process_time()
            call()
            times[name].append((time.perf_counter() - t0, time.process_time() - c0))
    return times


def fit_line(label: str, r: dict) -> str:
    return (f"  {label:<40} {r['seconds']:8.3f} {r['min']:7.3f}-{r['max']:<7.3f} "
            f"{r['cost']:10.4f} {r['runs']:>6} {'yes' if r['converged'] else 'no':>5}")


def solver_row(n_cells: int, n_samples: int, u: np.ndarray, y: np.ndarray, dt: float,
               fast_c=None) -> dict:
    """Interleaved tr / trf fits and the simulate (and fast C) time of the same data, in one
    row."""
    structure = mpl.MplStructure(n_cells=n_cells, dt=dt)
    runs: dict[str, list] = {"tr": [], "trf": []}
    sims: dict[str, list] = {"sim": [], "fast": []}
    for _ in range(FIT_REPEATS[n_samples]):
        for solver in ("tr", "trf"):
            runs[solver].append(hystkit_fit(u, y, structure, solver=solver))
            # after each fit, so that the denominator samples the load as the fits met it
            for name, times in simulate_seconds(structure, runs["tr"][-1]["params"], u,
                                                fast_c).items():
                sims[name] += times
    row = {solver: summarise(r) for solver, r in runs.items()}
    row.update(n=n_cells, size=n_samples)
    for name, times in sims.items():
        if times:
            row[name] = statistics.median(w for w, _ in times)
            row[f"{name}_cpu"] = statistics.median(c for _, c in times)
    return row


def print_solver_row(r: dict) -> None:
    new, old, sim, sim_cpu = r["tr"], r["trf"], r["sim"], r["sim_cpu"]
    fast, fast_cpu = r.get("fast"), r.get("fast_cpu")

    def part(f: dict) -> str:
        in_fast = (f"{f['seconds'] / fast:6.0f} {f['cpu'] / fast_cpu:6.0f}" if fast
                   else f"{'-':>6} {'-':>6}")
        return (f"{f['seconds']:7.3f} {f['seconds'] / sim:6.0f} {f['cpu'] / sim_cpu:6.0f} "
                f"{in_fast} {f['cost']:11.6f} {f['runs']:>5} "
                f"{'yes' if f['converged'] else 'no':>4}")

    fast_ms = f"{fast * 1e3:7.2f}" if fast else f"{'-':>7}"
    print(f"  {r['n']:>2} {r['size']:>7} {sim * 1e3:7.2f} {fast_ms} | {part(new)} | "
          f"{part(old)} | {old['seconds'] / new['seconds']:5.2f} {old['cpu'] / new['cpu']:5.2f} "
          f"{abs(new['cost'] - old['cost']) / old['cost']:8.1e}", flush=True)


def print_fit_table(fast_c=None) -> None:
    u8, y8, dt = fit_data()
    # Warm-up outside the timed runs: the first call of each path pays the kernel load.
    for solver in ("tr", "trf"):
        hystkit_fit(u8[:500], y8[:500], mpl.MplStructure(n_cells=1, dt=dt), solver=solver)
    print("Table 2. fit_mpl in simulations' worth (fit wall time / one mpl.simulate of the same "
          "data, same N, same run),")
    print(f"  virtual sine fitting recording(s) from seed {FIT_SEED}, dt = {dt:.3f} s, direct "
          f"mode; tr = default solver (normal equations), trf = previous (dense Jacobian);")
    print(f"  interleaved tr, trf x {FIT_REPEATS[8000]} (8000 samples) / "
          f"x {FIT_REPEATS[128_000]} (128k), medians; sim = median of all simulate calls, "
          f"{SIM_TIMING_REPEATS} after each fit; runs = FitResult.n_evaluations")
    print("  (tr: model runs, each yielding cost and normal equations; trf: residual + "
          "Jacobian evaluations, one kernel run each pair); cost = SSE (eq. 5.9)")
    print("  sims = fit / simulate by wall time; cpu = the same by process CPU time "
          "(time.process_time), which a loaded machine distorts far less")
    print(f"  C ms = the fast C reference (_c_fast_reference.c, cc {' '.join(FAST_FLAGS)}), "
          f"timed interleaved with each simulate call; Csims / Ccpu = fit / fast C by wall / "
          f"CPU time (issue 29.5: <= 100 at 1 cell, <= 300 at 3 cells, 8000 samples)")
    head = (f"  {'N':>2} {'samples':>7} {'sim ms':>7} {'C ms':>7} | {'tr s':>7} {'sims':>6} "
            f"{'cpu':>6} {'Csims':>6} {'Ccpu':>6} {'tr cost':>11} {'runs':>5} {'conv':>4} | "
            f"{'trf s':>7} {'sims':>6} {'cpu':>6} {'Csims':>6} {'Ccpu':>6} {'trf cost':>11} "
            f"{'runs':>5} {'conv':>4} | {'trf/tr':>5} {'cpu':>5} {'|dcost|':>8}")
    print(head)
    print("  " + "-" * (len(head) - 2))
    for size in FIT_SIZES:
        u, y, _ = (u8, y8, dt) if size == u8.size else fit_data(size)
        for n in FIT_CELLS[:1] if QUICK and size != u8.size else FIT_CELLS:
            print_solver_row(solver_row(n, size, u, y, dt, fast_c))
    print("  trf/tr = ratio of median wall times (cpu: of median CPU times); "
          "|dcost| = |SSE_tr - SSE_trf| / SSE_trf")
    print()

    structure = mpl.MplStructure(n_cells=1, dt=dt)
    one = repeated(lambda: hystkit_fit(u8, y8, structure, starts=default_starts(structure)[:1]),
                   FIT_REPEATS[8000])
    ref = repeated(lambda: fd_reference_fit(u8, y8, structure), FIT_REPEATS[8000])
    print("  Reference, N = 1, 8000 samples, same first start, theta0 and bounds "
          "(wall time, median of 3):")
    head = f"  {'':<40} {'median s':>8} {'min-max s':>15} {'cost':>10} {'runs':>6} {'conv.':>5}"
    print(head)
    print(fit_line("hystkit fit_mpl (tr), start [0] only", one))
    print(fit_line("scipy least_squares '2-point' + simulate", ref))
    print(f"  time ratio scipy-FD / hystkit: {ref['seconds'] / one['seconds']:.2f}x on the same "
          f"single start")
    print("  Document's reference: MATLAB patternsearch took about 60 s on 6 cores (paper 9.2); "
          "different data and machine, for scale only.")
    print()


# ----------------------------------------------------------------------------- paired

def pair_worker(fast_c) -> None:
    """One side of a --pair round: tr fits at 8000 samples, one JSON line on stdout."""
    u, y, dt = fit_data()
    hystkit_fit(u[:500], y[:500], mpl.MplStructure(n_cells=1, dt=dt))  # kernel load
    rows = {}
    for n in FIT_CELLS:
        structure = mpl.MplStructure(n_cells=n, dt=dt)
        fits, fast = [], []
        for _ in range(FIT_REPEATS[8000]):
            fits.append(hystkit_fit(u, y, structure))
            fast += simulate_seconds(structure, fits[-1]["params"], u, fast_c)["fast"]
        fast_cpu = statistics.median(c for _, c in fast)
        cpu = statistics.median(f["cpu"] for f in fits)
        rows[n] = {"runs": fits[-1]["runs"], "cost": fits[-1]["cost"], "cpu": cpu,
                   "converged": fits[-1]["converged"], "ccpu": cpu / fast_cpu}
    print(json.dumps(rows))


def print_pair_table(before_root: Path) -> None:
    trees = {"before": before_root / "src", "after": Path(__file__).resolve().parents[1] / "src"}
    rounds: dict[str, list[dict]] = {name: [] for name in trees}
    for _ in range(ROUNDS):
        for name, src in trees.items():  # A B A B
            env = {**os.environ, "PYTHONPATH": str(src)}
            out = subprocess.run([sys.executable, __file__, "--pair-worker"], env=env,
                                 capture_output=True, text=True, check=True)
            rounds[name].append(json.loads(out.stdout.strip().splitlines()[-1]))
    print(f"Paired fit cost, tr solver, 8000 samples (seed {FIT_SEED} sine): before = "
          f"{trees['before']}, after = {trees['after']}, {ROUNDS} rounds A B")
    print("  Ccpu = fit CPU / fast C simulate CPU (median of the round's 3 fits and their "
          "simulate calls); ratio = after / before per round")
    head = (f"  {'N':>2} | {'runs':>9} | {'SSE before':>17} {'SSE after':>17} {'rel':>9} | "
            f"{'conv':>7} | {'Ccpu before':>11} {'after':>6} | {'ratio med':>9} {'range':>11}")
    print(head)
    print("  " + "-" * (len(head) - 2))
    for n in map(str, FIT_CELLS):
        b, a = ([r[n] for r in rounds[name]] for name in ("before", "after"))
        ratios = [ra["ccpu"] / rb["ccpu"] for ra, rb in zip(a, b)]
        cb, ca = b[-1]["cost"], a[-1]["cost"]
        conv = f"{'y' if b[-1]['converged'] else 'n'}->{'y' if a[-1]['converged'] else 'n'}"
        print(f"  {n:>2} | {b[-1]['runs']:>4}->{a[-1]['runs']:<4} | {cb:17.12f} {ca:17.12f} "
              f"{(ca - cb) / cb:+9.1e} | {conv:>7} | "
              f"{statistics.median(r['ccpu'] for r in b):11.0f} "
              f"{statistics.median(r['ccpu'] for r in a):6.0f} | "
              f"{statistics.median(ratios):9.2f} {min(ratios):5.2f}-{max(ratios):<5.2f}")
    print("  rounds (Ccpu before -> after): " + "; ".join(
        f"N={n}: " + " ".join(f"{rb[n]['ccpu']:.0f}->{ra[n]['ccpu']:.0f}"
                              for rb, ra in zip(rounds["before"], rounds["after"]))
        for n in map(str, FIT_CELLS)))
    print()


# ----------------------------------------------------------------------------- main

def find_compiler() -> str | None:
    for name in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def main() -> int:
    t_total = time.perf_counter()
    cc = find_compiler()
    if PAIR_WORKER:
        with tempfile.TemporaryDirectory(prefix="hystkit-bench-") as workdir:
            pair_worker(fast_mpl(cc, Path(workdir)))
        return 0
    print_machine(cc)
    if PAIR:
        print_pair_table(Path(PAIR))
        print(f"Total benchmark time {time.perf_counter() - t_total:.1f} s")
        return 0
    with tempfile.TemporaryDirectory(prefix="hystkit-bench-") as workdir:
        c_func, c_seconds = build_c_reference(cc, workdir) if cc else (None, None)
        # Compile costs first: the tables' warm-ups would otherwise hide the first call.
        if not FIT_ONLY:
            print_compile_costs(c_seconds)
            print_simulation_table(c_func, cc)
        print_fit_table(fast_mpl(cc, Path(workdir)) if cc else None)
    print(f"Total benchmark time {time.perf_counter() - t_total:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
