"""Throughput and memory of ``hystkit preprocess`` on long raw recordings at 6.25 MHz.

Run:  /tmp/venv/bin/python benchmarks/bench_preprocess.py [--quick]   (about 3 minutes on 2 cores)

The virtual sensor's raw mode writes the sine experiment at the Handyscope rate of sec. 4.3.2
(6.25 MHz; columns time float64, v1, v2, merged encoder float32; Parquet, one row group per
2**20 samples) to a temporary folder, twice: SHORT and LONG seconds. Each file is then
preprocessed (eq. 4.3 per sample, encoder level survey + debounce + quadrature counting, FIR
decimation 6.25 MHz -> 10 kHz -> 400 Hz, 20 Hz zero-phase Butterworth, 40 Hz) in a fresh
Python process, after a small warm-up file of the same format there, so that numba's
compilation or cache loading is not timed.

Table 1 -- per length: wall and CPU time (CPU = both threads: the reader thread decodes Parquet
while the main thread computes), throughput in samples per second *per channel* (a sample is
one row: time, v1, v2, encoder), the real-time factor at 6.25 MHz (> 1: faster than the scope
records), tracemalloc's peak of traced allocations (NumPy arrays included) during the run, and
the process's peak RSS during the run (Linux VmHWM, reset before the run through
/proc/self/clear_refs; ru_maxrss would carry the parent's peak over exec). Memory must not grow with length: the pipeline holds one chunk, a
few decimator buffers and the 400 Hz intermediate signal (3 x 8 bytes x 400 Hz: 2.9 MB for
5 minutes).
Table 2 -- the same short file with chunk sizes 2**16, 2**18 (default), 2**20, 2**22: memory is
set by the chunk size, and larger chunks are not faster (they fall out of the caches).
Table 3 -- the same recording as CSV (text parsing with pandas, one thread) for comparison.
Last -- the extrapolation to the document's 5-minute recording at 6.25 MHz (1.875e9 samples
per channel), from the LONG run's throughput; not measured (it would need 38 GB of disk).

The machine is shared: the header shows the load average; CPU time is less disturbed by other
processes than wall time.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np
import pyarrow

import hystkit
from hystkit.sensors import ScopeSettings, simulate_raw

FS = 6.25e6
SHORT, LONG = 4.0, 32.0  # seconds of recording
QUICK = (1.0, 4.0)
CHUNKS = (1 << 16, 1 << 18, 1 << 20, 1 << 22)
DEFAULT_CHUNK = 1 << 18
FIVE_MINUTES = 300 * FS

# Runs in a fresh interpreter: argv = raw file, warm-up file, chunk size. Prints JSON.
_CHILD = r"""
import json, sys, time, tracemalloc
from hystkit.preprocess import PreprocessSettings, preprocess_raw

def status(key):  # kB -> MB, from the kernel's view of this process
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) / 1024 for line in f if line.startswith(key))

path, warm, chunk = sys.argv[1], sys.argv[2], int(sys.argv[3])
settings = PreprocessSettings(r_bridge=10e3, v_supply=2.0, chunk_size=chunk)
preprocess_raw(warm, settings)  # loads numba's cache, warms the allocator
rss_before = status("VmRSS:")
with open("/proc/self/clear_refs", "w") as f:  # reset the peak RSS (VmHWM) to the current RSS
    f.write("5")
tracemalloc.start()
wall, cpu = time.perf_counter(), time.process_time()
result = preprocess_raw(path, settings)
wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
traced = tracemalloc.get_traced_memory()[1] / 2**20
print(json.dumps({"wall": wall, "cpu": cpu, "traced_mb": traced, "rss_mb": status("VmHWM:"),
                  "rss_before_mb": rss_before, "n": result.report.n_samples,
                  "n_illegal": result.report.n_illegal, "n_edges": result.report.n_edges}))
"""

def machine() -> str:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    load = ", ".join(f"{v:.2f}" for v in os.getloadavg())
    return (f"Machine\n  platform     {platform.platform()}\n  CPU          {cpu}; "
            f"os.cpu_count() = {os.cpu_count()}, usable = {len(os.sched_getaffinity(0))}\n"
            f"  load average {load} (1, 5, 15 min) at start\n"
            f"  python       {platform.python_version()}; numpy {np.__version__}, numba "
            f"{numba.__version__}, pyarrow {pyarrow.__version__}, hystkit {hystkit.__version__}")


def run_child(path: Path, warm: Path, chunk: int) -> dict:
    out = subprocess.run([sys.executable, "-c", _CHILD, str(path), str(warm), str(chunk)],
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def row(label: str, size_mb: float, r: dict) -> str:
    rate = r["n"] / r["wall"]
    return (f"  {label:<22}{r['n'] / 1e6:>9.1f}{size_mb:>9.0f}{r['wall']:>8.2f}{r['cpu']:>8.2f}"
            f"{rate / 1e6:>10.2f}{rate / FS:>8.2f}{r['n'] / r['cpu'] / 1e6:>10.2f}"
            f"{r['traced_mb']:>10.1f}{r['rss_mb']:>9.0f}{r['rss_before_mb']:>9.0f}")


HEAD = (f"  {'':<22}{'M samp.':>9}{'file MB':>9}{'wall s':>8}{'CPU s':>8}{'M samp/s':>10}"
        f"{'x real':>8}{'M/CPU s':>10}{'traced MB':>10}{'RSS MB':>9}{'RSS0 MB':>9}")
NOTE = ("  M samp/s = samples per second per channel (wall); x real = that / 6.25 MHz; "
        "M/CPU s = per CPU second;\n  traced MB = tracemalloc peak during the run; RSS MB = "
        "peak RSS during the run (VmHWM, reset before it);\n  RSS0 MB = RSS before the run "
        "(the interpreter, NumPy, SciPy, pandas, pyarrow, numba and their code)")


def main() -> None:
    short, long_ = QUICK if "--quick" in sys.argv else (SHORT, LONG)
    t_start = time.perf_counter()
    print(machine())
    with tempfile.TemporaryDirectory(prefix="hystkit-bench-") as folder:
        folder = Path(folder)
        # Warm-up files in both formats: CSV gives float64 arrays, Parquet float32, and numba
        # compiles (or loads from its cache) one kernel version for each.
        warm = folder / "warm_pq.parquet"
        warm_csv = folder / "warm.csv"
        for path in (warm, warm_csv):
            simulate_raw(path, "sine", 0, scope=ScopeSettings(fs=1e5), duration=1.0)
        files = {}
        for seconds in (short, long_):
            path = folder / f"sine_{seconds:g}s.parquet"
            t0 = time.perf_counter()
            simulate_raw(path, "sine", 1, scope=ScopeSettings(fs=FS), duration=seconds)
            files[seconds] = path
            print(f"  generated {path.name}: {seconds * FS / 1e6:.0f} M samples per channel, "
                  f"{path.stat().st_size / 2**20:.0f} MB in {time.perf_counter() - t0:.1f} s")

        print(f"\nTable 1. Preprocessing at {FS / 1e6:g} MHz, Parquet, default chunk 2**18, "
              "each run in a fresh process")
        print(HEAD)
        results = {}
        for seconds, path in files.items():
            results[seconds] = run_child(path, warm, DEFAULT_CHUNK)
            print(row(f"{seconds:g} s recording", path.stat().st_size / 2**20, results[seconds]))
        print(NOTE)
        a, b = results[short], results[long_]
        print(f"  memory growth from {short:g} s to {long_:g} s: traced "
              f"{b['traced_mb'] - a['traced_mb']:+.1f} MB, peak RSS "
              f"{b['rss_mb'] - a['rss_mb']:+.0f} MB for {long_ / short:g}x the samples; "
              f"illegal transitions {a['n_illegal']}, {b['n_illegal']} of "
              f"{a['n_edges']}, {b['n_edges']}")

        print(f"\nTable 2. Chunk size, {short:g} s recording")
        print(HEAD)
        for chunk in CHUNKS:
            r = results[short] if chunk == DEFAULT_CHUNK else run_child(files[short], warm, chunk)
            print(row(f"chunk 2**{chunk.bit_length() - 1}", files[short].stat().st_size / 2**20,
                      r))

        csv = folder / "sine_csv.csv"
        simulate_raw(csv, "sine", 1, scope=ScopeSettings(fs=FS), duration=1.0)
        print("\nTable 3. CSV instead of Parquet (1 s recording; pandas text parsing)")
        print(HEAD)
        print(row("1 s recording, CSV", csv.stat().st_size / 2**20, run_child(csv, warm_csv,
                                                                         DEFAULT_CHUNK)))

    rate = b["n"] / b["wall"]
    cpu_rate = b["n"] / b["cpu"]
    print(f"\nExtrapolation (not measured): the document's 5-minute recording at 6.25 MHz, "
          f"{FIVE_MINUTES / 1e9:.3f} G samples per channel, as Parquet ({FIVE_MINUTES * 20 / 1e9:.0f} "
          f"GB):\n  about {FIVE_MINUTES / rate / 60:.1f} min wall at the {long_:g} s run's rate "
          f"({rate / FS:.2f}x real time; {FIVE_MINUTES / cpu_rate / 60:.1f} CPU-min), memory as "
          f"in table 1 plus {3 * 8 * 400 * 300 / 2**20:.1f} MB of 400 Hz intermediate signal")
    print(f"\nTotal benchmark time {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    main()
