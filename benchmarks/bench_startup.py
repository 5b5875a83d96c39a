"""Start-up time of the ``hystkit`` command line: lazy imports against the eager revision.

Run:  python benchmarks/bench_startup.py [--repeats N] [--base REV]   (about a minute)

Whole-process wall time, from starting ``python -m hystkit ...`` to its exit, of commands that
do (almost) no work, so what is measured is the import and parser cost every command pays:
``--version``, ``--help``, ``fit --help`` and ``evaluate`` of a missing model file (one error
line). ``A`` is revision ``--base`` (default 59e683a, the last commit before the lazy imports),
extracted with ``git archive`` into a temporary folder and run with ``PYTHONPATH`` pointing
there; ``B`` is this working tree's ``src``. Same interpreter, same installed libraries; A and B
alternate (A B A B ...) after one warm-up each, so bursts of load hit both alike. Reported:
the median of each and the median of the paired ratios A/B. ``python -c "import numpy"`` is
printed as the floor any numpy program pays (issue 11 asks for ``--help``/``--version`` within
3x of it).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BASE = "59e683a"  # the last commit before the lazy imports (issue 11)
COMMANDS = {
    "--version": ["--version"],
    "--help": ["--help"],
    "fit --help": ["fit", "--help"],
    "evaluate missing": ["evaluate", "missing-model.json", "missing.csv"],
}


def _machine() -> str:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"platform {platform.platform()}; cpus {os.cpu_count()}; load average {load}\n"
            f"python {platform.python_version()} ({sys.executable})")


def _extract(rev: str, into: Path) -> Path:
    archive = into / "src.tar"
    with archive.open("wb") as f:
        subprocess.run(["git", "-C", str(REPO), "archive", rev, "src"], stdout=f, check=True)
    with tarfile.open(archive) as tar:
        tar.extractall(into, filter="data")
    return into / "src"


def _wall(argv: list[str], src: Path | None) -> float:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, *argv], env=env, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, check=False, cwd=tempfile.gettempdir())
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--base", default=BASE)
    args = parser.parse_args()
    print("hystkit start-up: whole-process wall time [s], median of "
          f"{args.repeats} interleaved runs")
    print(_machine())
    with tempfile.TemporaryDirectory() as tmp:
        src_a = _extract(args.base, Path(tmp))
        src_b = REPO / "src"
        numpy_floor = [_wall(["-c", "import numpy"], None) for _ in range(args.repeats + 1)][1:]
        print(f"A = {args.base} (eager imports), B = working tree (lazy imports)\n")
        print(f"{'command':<20}{'A median':>10}{'B median':>10}{'A/B':>8}{'B / numpy':>11}")
        floor = statistics.median(numpy_floor)
        for label, cmd in COMMANDS.items():
            argv = ["-m", "hystkit", *cmd]
            _wall(argv, src_a), _wall(argv, src_b)  # warm-up: file cache, numba cache
            a, b = [], []
            for _ in range(args.repeats):
                a.append(_wall(argv, src_a))
                b.append(_wall(argv, src_b))
            ratio = statistics.median(x / y for x, y in zip(a, b, strict=True))
            print(f"{label:<20}{statistics.median(a):>10.3f}{statistics.median(b):>10.3f}"
                  f"{ratio:>7.1f}x{statistics.median(b) / floor:>10.1f}x")
        label = 'python -c "import numpy" (B column)'
        print(f"{label:<30}{floor:>10.3f}")


if __name__ == "__main__":
    main()
