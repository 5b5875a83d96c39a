"""Latency of the streaming compensator in Python: ``Stream.step``, ``Stream.process`` on chunks
of 64 samples, and a plain-Python loop over the family's readable ``step`` as the reference.

Run:  python benchmarks/bench_stream.py [--quick]      (a few minutes on 2 cores; --quick: a
      quarter of the samples and repeats)

Compensators are fitted (direct mode) on the virtual sensor's sine run (8000 samples at 40 Hz)
and run on its decay run. Per family and method, every repeat times the same samples; methods
alternate inside each repeat (A B C A B C ...) so bursts of load hit all alike; the table gives
the median over repeats of each repeat's median per-sample latency (and the p99 of ``step``).

- ``step``: ``Stream.step(v)`` per sample (the whole data path: centring, scaling, the family's
  compiled run of one sample, guards, flags);
- ``process/64``: ``Stream.process`` on chunks of 64 samples, time per chunk / 64;
- ``python loop``: the family's readable ``step(structure, params, x, u)`` in a Python loop on
  the normalised sensor: the model alone, no conventions (the reference the issue asks for).

``same`` says whether the chunked stream reproduced ``Compensator.estimate`` bit for bit (it
does the same work). :func:`python_latency` is the measurement for one compensator, importable
by other benchmarks (``benchmarks/bench_export.py`` adds the C and MATLAB rows).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from hystkit.compensation import Compensator, Stream, fit_compensator
from hystkit.sensors import simulate_experiment

FAMILIES = (("mpl", 1), ("mpl", 3), ("mpl-poly", 3), ("pi", 10), ("preisach", 20),
            ("ladder", 3))
CHUNK = 64


def _per_sample_step(comp: Compensator, sensor: np.ndarray) -> np.ndarray:
    stream = Stream(comp)
    times = np.empty(sensor.size)
    clock = time.perf_counter
    for k, v in enumerate(sensor.tolist()):
        t0 = clock()
        stream.step(v)
        times[k] = clock() - t0
    return times


def _per_sample_chunks(comp: Compensator, sensor: np.ndarray, chunk: int) -> np.ndarray:
    stream = Stream(comp)
    times = []
    clock = time.perf_counter
    for k in range(0, sensor.size - chunk + 1, chunk):
        part = sensor[k:k + chunk]
        t0 = clock()
        stream.process(part)
        times.append((clock() - t0) / chunk)
    return np.array(times)


def _per_sample_python(comp: Compensator, sensor: np.ndarray) -> np.ndarray:
    family, structure, params = comp.family, comp.structure, comp.params
    u = comp.normalised_sensor(sensor).tolist()
    x = family.rest_state(structure, params, u[0])
    times = np.empty(len(u))
    clock = time.perf_counter
    for k, v in enumerate(u):
        t0 = clock()
        _, x = family.step(structure, params, x, v)
        times[k] = clock() - t0
    return times


def python_latency(comp: Compensator, sensor: np.ndarray, *, repeats: int = 5,
                   chunk: int = CHUNK) -> dict[str, float]:
    """Per-sample latency [µs] of ``Stream.step`` (median and p99), ``Stream.process`` on
    chunks of ``chunk`` samples and the plain-Python loop, medians over ``repeats`` interleaved
    repeats on ``sensor`` (raw sensor samples). Warms up (compiles) first."""
    Stream(comp).process(sensor[:2])
    Stream(comp).step(float(sensor[0]))
    runs: dict[str, list[float]] = {"step_us": [], "step_p99_us": [], "process_chunk_us": [],
                                    "python_loop_us": []}
    for _ in range(repeats):
        step = _per_sample_step(comp, sensor) * 1e6
        runs["step_us"].append(float(np.median(step)))
        runs["step_p99_us"].append(float(np.percentile(step, 99)))
        runs["process_chunk_us"].append(float(np.median(_per_sample_chunks(comp, sensor,
                                                                           chunk))) * 1e6)
        runs["python_loop_us"].append(float(np.median(_per_sample_python(comp, sensor))) * 1e6)
    return {key: statistics.median(values) for key, values in runs.items()}


def _same_as_offline(comp: Compensator, recording) -> bool:
    stream = Stream(comp)
    parts = [stream.process(recording.sensor[k:k + CHUNK])
             for k in range(0, recording.n_samples, CHUNK)]
    return bool(np.array_equal(np.concatenate(parts), comp.estimate(recording)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer samples and repeats")
    args = parser.parse_args()
    n_samples, repeats = (500, 3) if args.quick else (2000, 7)
    fit_rec, use_rec = simulate_experiment("sine", 1), simulate_experiment("decay", 2)
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load "
          f"{load}; {n_samples} samples, {repeats} repeats; µs per sample (medians)")
    print(f"{'model':<14} {'step':>8} {'step p99':>9} {'process/64':>11} {'python loop':>12} "
          f"{'same':>5}")
    for name, size in FAMILIES:
        comp = fit_compensator(fit_rec, size, model=name, diagnose=False)
        found = python_latency(comp, use_rec.sensor[:n_samples], repeats=repeats)
        print(f"{f'{name} {size}':<14} {found['step_us']:>8.1f} {found['step_p99_us']:>9.1f} "
              f"{found['process_chunk_us']:>11.2f} {found['python_loop_us']:>12.1f} "
              f"{_same_as_offline(comp, use_rec)!s:>5}", flush=True)
    print(f"# load at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
