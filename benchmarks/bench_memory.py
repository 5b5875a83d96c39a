"""Peak memory and wall time of reading, ``fit``, ``evaluate`` and ``compensate`` (issue 10).

Run:  python benchmarks/bench_memory.py [--quick] [--fit-rows N] [--old-reader REV] [--only-fit]

Synthetic recordings of 0.1, 1 and 5 million rows (``--quick``: 0.1 and 1 million): a long sine
position (10 mm, 0.05 Hz, 40 Hz sampling) through a simple hysteretic map (the sensor lags the
position by 0.3 rad and bends with a cubic term, plus 1e-4 noise), written by
``write_recording`` as CSV and as Parquet. Each command then runs in a fresh child process
(``python -m hystkit ...``) started by a fresh measuring process, whose
``getrusage(RUSAGE_CHILDREN).ru_maxrss`` is then the child's peak RSS alone.

- ``read``: ``read_recording`` only (the reader's share);
- ``fit``: ``hystkit fit --model mpl --cells 1`` (the smallest mPL, 5 parameters, exact
  Jacobian; ``--fit-rows N`` skips fits above N rows);
- ``evaluate``/``compensate``: with an mPL 1-cell model fitted once on the 0.1 M CSV.

``--only-fit`` runs only the ``fit`` rows (and their 1000-row base), at 1 and 5 million rows.

Table 1 shows per command: the data's own size (rows x 3 columns x 8 bytes), wall time, peak
RSS, and peak RSS over the data, raw and after subtracting the same command's peak on a
1000-row file of the same format (``base``: interpreter, libraries, numba compilation).
``--old-reader REV`` adds a ``read (REV)`` row with ``read_recording`` from that git revision
(e.g. 87b1774, the all-text reader before issue 10).
Table 2: the cost of reading ``.mat`` in a child process (see ``hystkit.io._mat_reader``) against
scipy's ``loadmat`` in-process, min of 5.

No pass/fail; the header records the machine and its load (the machine is shared).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow

import hystkit
from hystkit.io import Recording, read_recording, write_recording

ROWS = (100_000, 1_000_000, 5_000_000)
QUICK_ROWS = (100_000, 1_000_000)
FIT_ROWS = 5_000_000
FS = 40.0

# Runs the command in argv[1:] as its only child; prints wall time and that child's peak RSS.
_MEASURE = r"""
import json, resource, subprocess, sys, time
start = time.perf_counter()
proc = subprocess.run(sys.argv[1:], capture_output=True, text=True)
wall = time.perf_counter() - start
print(json.dumps({"code": proc.returncode, "wall": wall, "err": proc.stderr[-400:],
                  "rss_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024}))
"""
_READ = "import sys; from hystkit.io import read_recording; read_recording(sys.argv[1])"
BASE_ROWS = 1000  # each command's memory without data: the same command on 1000 rows
_OLD_READ = """
import importlib.util, sys
spec = importlib.util.spec_from_file_location("old_recording", sys.argv[2])
module = importlib.util.module_from_spec(spec)
sys.modules["old_recording"] = module  # dataclasses look their module up there
spec.loader.exec_module(module)
module.read_recording(sys.argv[1])
"""


def machine() -> str:
    cpu = "unknown"
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    load = ", ".join(f"{v:.2f}" for v in os.getloadavg())
    return (f"Machine\n  platform     {platform.platform()}\n  CPU          {cpu}; "
            f"os.cpu_count() = {os.cpu_count()}\n"
            f"  load average {load} (1, 5, 15 min) at start\n"
            f"  python       {platform.python_version()}; numpy {np.__version__}, pandas "
            f"{pd.__version__}, pyarrow {pyarrow.__version__}, hystkit {hystkit.__version__}")


def recording(n: int) -> Recording:
    time_s = np.arange(n) / FS
    phase = 2 * np.pi * 0.05 * time_s
    lagged = np.sin(phase - 0.3)
    noise = 1e-4 * np.random.default_rng(0).standard_normal(n)
    return Recording(time=time_s, position=10.0 * np.sin(phase),
                     sensor=0.02 * lagged + 0.002 * lagged**3 + noise)


def measure(*argv: object) -> dict:
    out = subprocess.run([sys.executable, "-c", _MEASURE, *map(str, argv)], check=True,
                         capture_output=True, text=True)
    result = json.loads(out.stdout.strip().splitlines()[-1])
    if result["code"] != 0:
        raise RuntimeError(f"{argv}: exit {result['code']}: {result['err']}")
    return result


def hystkit_cmd(*args: object) -> list[str]:
    return [sys.executable, "-m", "hystkit", *map(str, args)]


def mat_overhead(folder: Path) -> list[str]:
    from scipy.io import loadmat, savemat

    lines = []
    for n in (8000, 1_000_000):
        rec = recording(n)
        path = folder / f"r{n}.mat"
        savemat(path, {"time": rec.time, "position": rec.position, "sensor": rec.sensor})
        child = min(_timed(read_recording, path) for _ in range(5))
        inproc = min(_timed(loadmat, path) for _ in range(5))
        lines.append(f"  {n:>10,}{path.stat().st_size / 2**20:>9.1f}{inproc:>12.3f}"
                     f"{child:>12.3f}{child - inproc:>10.3f}")
    return lines


def _timed(call, *args: object) -> float:
    start = time.perf_counter()
    call(*args)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--fit-rows", type=int, default=FIT_ROWS)
    parser.add_argument("--old-reader", metavar="REV")
    parser.add_argument("--only-fit", action="store_true",
                        help="only the fit rows, at 1 and 5 million rows")
    args = parser.parse_args()
    started = time.perf_counter()
    print(machine())
    with tempfile.TemporaryDirectory(prefix="hystkit-bench-memory-") as tmp:
        folder = Path(tmp)
        old = None
        if args.old_reader:
            old = folder / "old_recording.py"
            old.write_text(subprocess.run(
                ["git", "show", f"{args.old_reader}:src/hystkit/io/_recording.py"],
                check=True, capture_output=True, text=True).stdout)
        rows = QUICK_ROWS if args.quick else ROWS
        if args.only_fit:
            rows = tuple(n for n in rows if n >= 1_000_000)
        files = {}
        for n in (BASE_ROWS, *rows):
            rec = recording(n)
            for suffix in (".csv", ".parquet"):
                files[n, suffix] = write_recording(rec, folder / f"r{n}{suffix}")
            del rec
        model = folder / "model.json"
        if not args.only_fit:
            measure(*hystkit_cmd("fit", files[rows[0], ".csv"], "--model", "mpl", "--cells",
                                 "1", "--out", model))
        print("Table 1. Peak RSS and wall time per command (fresh process each)")
        base: dict[tuple[str, str], float] = {}
        head = (f"  {'rows':>10}{'format':>9}{'file MB':>9}{'data MB':>9}  {'command':<14}"
                f"{'wall s':>8}{'peak MB':>9}{'peak/data':>10}{'(peak-base)/data':>18}")
        print(head)
        for n in (BASE_ROWS, *rows):
            data_mb = n * 3 * 8 / 2**20
            for suffix in (".csv", ".parquet"):
                path = files[n, suffix]
                commands = {} if args.only_fit else {"read": [sys.executable, "-c", _READ, path]}
                if old is not None and not args.only_fit:
                    commands[f"read ({args.old_reader[:7]})"] = [sys.executable, "-c", _OLD_READ,
                                                                 path, old]
                if n <= args.fit_rows:
                    commands["fit mpl 1"] = hystkit_cmd("fit", path, "--model", "mpl", "--cells",
                                                        "1", "--out", folder / "fitted.json",
                                                        "--force")
                if not args.only_fit:
                    commands["evaluate"] = hystkit_cmd("evaluate", model, path)
                    commands["compensate"] = hystkit_cmd("compensate", model, path, "--out",
                                                         folder / f"out{suffix}", "--force")
                for label, argv in commands.items():
                    r = measure(*argv)
                    if n == BASE_ROWS:
                        base[label, suffix] = r["rss_mb"]
                        extra = "base"
                    else:
                        extra = f"{(r['rss_mb'] - base[label, suffix]) / data_mb:.1f}"
                    print(f"  {n:>10,}{suffix[1:]:>9}{path.stat().st_size / 2**20:>9.1f}"
                          f"{data_mb:>9.1f}  {label:<14}{r['wall']:>8.1f}{r['rss_mb']:>9.0f}"
                          f"{r['rss_mb'] / data_mb:>10.1f}{extra:>18}", flush=True)
        if not args.only_fit:
            print("\nTable 2. Reading .mat in a child process vs scipy's loadmat in-process "
                  "(min of 5)")
            print(f"  {'samples':>10}{'file MB':>9}{'loadmat s':>12}{'hystkit s':>12}"
                  f"{'extra s':>10}")
            print("\n".join(mat_overhead(folder)))
    print(f"\nTotal benchmark time {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
