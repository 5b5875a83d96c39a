"""Speed of hystkit's closed-loop simulation against python-control and a plain Python loop.

Run:  /tmp/venv/bin/python benchmarks/bench_control.py      (about a minute on 2 cores)

The loop is the document's 5 s closed loop (ch. 7): r = 3 mm sin(pi t) (eq. 7.3), Ts = 5.04e-4 s,
so 9921 steps, plant 1 / (m s^2) (exact ZOH), the eq. 7.2 PID with the document's gains, the
"real" sensor S_r (3-cell mPL fitted on the virtual sensor's noise run) and the compensator
(3-cell mPL, direct mode, fitted on its sine run) -- scheme (a); scheme (b) adds S_m (3 cells).
Variants, all on the same ControlLoop and the same reference:

* ``hystkit``: ``hystkit.control.simulate_loop`` (validating wrapper + one numba kernel call),
* ``kernel``: the bare kernel ``_kernel.run`` with pre-packed arguments,
* ``Python``: ``simulate_loop_reference``, the readable plain-Python loop over block steps,
* ``python-control``: ``control.input_output_response`` on ``hystkit.control.loop_nlsys(loop)``
  (a discrete-time interconnection of ``nlsys`` blocks with the same equations).

Each variant's output is compared with hystkit's (max |y difference|, metres) to show they do
the same work. hystkit and the kernel: minimum of 15 interleaved repeats after a warm-up call;
the Python loop: minimum of 3; python-control: one run per scheme (about 10 s each). The numba
compile (or on-disk cache load) and the model fits are one-off costs, reported separately.
"""

from __future__ import annotations

import os
import platform
import time

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as bench_mpl.py: small fits, no threads

import control
import numba
import numpy as np

import hystkit
from hystkit import control as hc
from hystkit.control import _kernel

SECONDS = 5.0
REPEATS = 15
PY_REPEATS = 3


def machine() -> None:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "n/a"
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    print("Machine")
    print(f"  platform     {platform.platform()}; cpus {os.cpu_count()} (usable {usable})")
    print(f"  load average {load} (1, 5, 15 min) at start")
    print(f"  python       {platform.python_version()}; numpy {np.__version__}, numba "
          f"{numba.__version__}, python-control {control.__version__}, hystkit "
          f"{hystkit.__version__}")
    print()


def best_of(fn, repeats: int) -> float:
    fn()
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    t_total = time.perf_counter()
    machine()
    t0 = time.perf_counter()
    models = hc.fit_sensor_models()
    t_fit = time.perf_counter() - t0
    n = round(SECONDS / hc.TS)
    r = hc.sine_reference(n)
    rows = []
    t0 = time.perf_counter()
    hc.simulate_loop(hc.build_loop("direct", models), r[:10])
    t_first = time.perf_counter() - t0
    for scheme in hc.SCHEMES:
        loop = hc.build_loop(scheme, models)
        fast = hc.simulate_loop(loop, r)
        state = hc.rest_state(loop, float(r[0])).to_vector()
        args = loop.kernel_arguments()
        zeros = np.zeros(n)

        def kernel(loop=loop, state=state, args=args, zeros=zeros):
            return _kernel.run(r, zeros, zeros, zeros, state, *args)

        times = {"hystkit": float("inf"), "kernel": float("inf")}
        for fn in (lambda loop=loop: hc.simulate_loop(loop, r), kernel):
            fn()
        for _ in range(REPEATS):  # interleaved, so bursts of load hit both alike
            for name, fn in (("hystkit", lambda loop=loop: hc.simulate_loop(loop, r)),
                             ("kernel", kernel)):
                t0 = time.perf_counter()
                fn()
                times[name] = min(times[name], time.perf_counter() - t0)
        slow = hc.simulate_loop_reference(loop, r)
        times["Python"] = best_of(lambda loop=loop: hc.simulate_loop_reference(loop, r),
                                  PY_REPEATS - 1)
        sys = hc.loop_nlsys(loop)
        x0 = hc.loop_initial_state(loop, r0=float(r[0]))
        t_axis = np.arange(n) * hc.TS
        t0 = time.perf_counter()
        pc = control.input_output_response(sys, t_axis, [r, zeros, zeros], x0)
        times["python-control"] = time.perf_counter() - t0
        kernel_y = kernel()[0][0]
        diffs = {"hystkit": 0.0, "kernel": float(np.max(np.abs(kernel_y - fast.y))),
                 "Python": float(np.max(np.abs(slow.y - fast.y))),
                 "python-control": float(np.max(np.abs(pc.outputs[0] - fast.y)))}
        for name in ("hystkit", "kernel", "Python", "python-control"):
            rows.append((scheme, name, times[name], diffs[name], times[name] / times["hystkit"]))

    print("One-off costs (not in the table)")
    print(f"  fit_sensor_models (S_r, compensator, S_m; 3 cells each)  {t_fit:8.2f} s")
    print(f"  first simulate_loop call (numba compile or cache load)   {t_first * 1e3:8.1f} ms")
    print()
    print(f"Table. {SECONDS:g} s closed loop, {n} steps at Ts = {hc.TS} s, r = 3 mm sin(pi t); "
          f"S_r and compensator 3-cell mPL (+ S_m for weighting)")
    print("  hystkit/kernel: min of 15 interleaved repeats after warm-up; Python: min of 3; "
          "python-control: 1 run")
    print(f"  {'scheme':<10}{'variant':<16}{'ms / run':>12}{'us / step':>11}{'x hystkit':>11}"
          f"{'max|y diff| m':>15}")
    print("  " + "-" * 73)
    for scheme, name, seconds, diff, ratio in rows:
        print(f"  {scheme:<10}{name:<16}{seconds * 1e3:>12.2f}{seconds / n * 1e6:>11.3f}"
              f"{ratio:>11.1f}{diff:>15.1e}")
    print()
    print(f"Total benchmark time {time.perf_counter() - t_total:.1f} s")


if __name__ == "__main__":
    main()
