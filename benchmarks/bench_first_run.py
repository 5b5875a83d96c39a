"""The first run after installing against a later one: numba's cache empty vs filled (issue 29).

Run:  python benchmarks/bench_first_run.py [--repeats N] [--before REV] [--compare]
      [--out FILE]     (~6 min with the defaults on 2 cores; --compare adds ~4 min)

Whole-process wall time of ``python -m hystkit ...`` in a temporary folder, on the virtual
sensor's noise recording (seed 1, 8000 samples at 40 Hz) to fit and its sine recording (seed
2) to validate:

- ``fit DATA --out M.json`` (1 mPL cell, the default) and ``control --scheme direct
  --experiment sine``; with ``--compare`` also ``compare FIT VAL`` (every family);
- *cold*: ``NUMBA_CACHE_DIR`` a fresh empty folder, as after installing (every kernel the
  command needs is compiled); *warm*: a folder that a run of the same command filled before
  (untimed), as every later run;
- for this tree (``after``, its ``src`` copied as it is at the start) and for the source of
  git revision REV (``--before``, ``git archive`` into a temporary folder; default 12c336a, the commit before issue 29's
  caching: the control loop was compiled by every process and ``fit_seconds`` held the
  compilation). Children run with ``PYTHONPATH`` on the variant's ``src`` and Python's
  bytecode cache in a temporary ``PYTHONPYCACHEPREFIX`` (filled by the untimed warm-up run).

Paired and interleaved: each repeat runs, for every command, the variants cold one after the
other, then warm (after before, before after in the next repeat: A B B A ...), so bursts of
the machine's load hit all alike; reported are the medians and the median of the per-repeat
cold / warm ratios. Beside the times: the model
file's ``fit_seconds`` (the fit alone, not the compilation, since issue 29), control's
``compile_seconds`` (compiling or loading its loop kernel) and whether the program's
one-line compilation notice was on stderr. Last, one cold ``hystkit warm`` (after only).
"""

from __future__ import annotations

import argparse
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

REPO = Path(__file__).resolve().parents[1]
BEFORE = "12c336a"  # the last commit before issue 29's caching
COMMANDS = {
    "fit": ["fit", "fit.csv", "--out", "model.json", "--force"],
    "control": ["control", "--scheme", "direct", "--experiment", "sine", "--out", "ctl",
                "--force"],
    "compare": ["compare", "fit.csv", "val.csv", "--out", "cmp", "--force"],
}
NOTICE = "compiling numba kernels"  # part of hystkit.cli._main.COMPILING_NOTICE


def _machine() -> str:
    import numba

    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"platform {platform.platform()}; cpus {os.cpu_count()}; load average {load} at "
            f"start\npython {platform.python_version()}, numba {numba.__version__}")


def _source(variant: str, rev: str, tmp: Path) -> Path:
    """The ``src`` folder of `variant`, copied into `tmp`: this tree's as it is (so that edits
    during the run do not invalidate the cache), or revision `rev`'s."""
    folder = tmp / f"src-{variant}"
    if variant == "after":
        shutil.copytree(REPO / "src", folder / "src",
                        ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    else:
        folder.mkdir()
        archive = subprocess.run(["git", "-C", str(REPO), "archive", rev, "src"],
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    return folder / "src"


def _found(data: object, key: str) -> float | None:
    """The first value of `key` in nested JSON `data`."""
    if isinstance(data, dict):
        if key in data:
            return data[key]
        data = list(data.values())
    if isinstance(data, list):
        for item in data:
            value = _found(item, key)
            if value is not None:
                return value
    return None


def _run(command: str, src: Path, cwd: Path, cache: Path) -> dict:
    """One run as the program: wall seconds, notice on stderr, fit_seconds / compile_seconds."""
    env = {**os.environ, "PYTHONPATH": str(src), "NUMBA_CACHE_DIR": str(cache),
           "PYTHONPYCACHEPREFIX": str(cwd / "pycache")}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "hystkit", *COMMANDS[command]], cwd=cwd,
                          env=env, capture_output=True, text=True, check=False)
    seconds = time.perf_counter() - t0
    if done.returncode not in (0, 3):
        raise RuntimeError(f"{command} exited {done.returncode}: {done.stderr[-500:]}")
    row = {"seconds": seconds, "notice": NOTICE in done.stderr}
    if command == "fit":
        row["inner"] = _found(json.loads((cwd / "model.json").read_text()), "fit_seconds")
    elif command == "control":
        row["inner"] = _found(json.loads((cwd / "ctl" / "metrics.json").read_text()),
                              "compile_seconds")
    return row


def _median(rows: list[dict], key: str) -> float | None:
    values = [r[key] for r in rows if r.get(key) is not None]
    return statistics.median(values) if values else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--before", default=BEFORE, metavar="REV",
                        help=f"git revision to compare with (default {BEFORE}; 'none': skip)")
    parser.add_argument("--compare", action="store_true", help="also time `hystkit compare`")
    parser.add_argument("--out", type=Path, default=None,
                        help="also write the report here (benchmarks/last_run_first_run.txt)")
    args = parser.parse_args()
    from hystkit.io import write_recording
    from hystkit.sensors import simulate_experiment

    commands = ["fit", "control"] + (["compare"] if args.compare else [])
    variants = ["after"] + ([] if args.before == "none" else [f"before {args.before}"])
    title = (f"hystkit's first run with numba's cache empty (cold) vs filled (warm): "
             f"whole-process wall time [s], medians of {args.repeats} interleaved repeats")
    lines = [title, _machine(), ""]
    t_total = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        write_recording(simulate_experiment("noise", 1), tmp / "fit.csv")
        write_recording(simulate_experiment("sine", 2), tmp / "val.csv")
        srcs = {v: _source(v.split()[0], args.before, tmp) for v in variants}
        warm = {(v, c): tmp / f"warm-{i}-{c}" for i, v in enumerate(variants) for c in commands}
        for (variant, command), cache in warm.items():  # untimed: fills the warm caches
            _run(command, srcs[variant], tmp, cache)
        rows: dict = {key: {"cold": [], "warm": []} for key in warm}
        for repeat in range(args.repeats):
            order = variants if repeat % 2 == 0 else variants[::-1]  # A B, then B A
            for command in commands:
                for state in ("cold", "warm"):
                    for variant in order:
                        cache = (warm[variant, command] if state == "warm" else
                                 tmp / f"cold-{repeat}-{variant.split()[0]}-{command}")
                        rows[variant, command][state].append(
                            _run(command, srcs[variant], tmp, cache))
        t_warm = time.perf_counter()
        warm_up = _run_warm(srcs["after"], tmp, tmp / "cold-warm-command")
        t_warm = time.perf_counter() - t_warm
    inner = {"fit": "fit_seconds", "control": "loop compile s", "compare": ""}
    lines.append(f"{'command':<9}{'variant':<16}{'cold s':>8}{'warm s':>8}{'cold/warm':>11}"
                 f"{'':>3}{'inner: cold / warm':<34}{'notice cold / warm':>19}")
    for (variant, command), by in rows.items():
        ratio = statistics.median(c["seconds"] / w["seconds"]
                                  for c, w in zip(by["cold"], by["warm"], strict=True))
        cold_inner, warm_inner = _median(by["cold"], "inner"), _median(by["warm"], "inner")
        shown = (f"{inner[command]} {cold_inner:.3f} / {warm_inner:.3f}"
                 if cold_inner is not None else "")
        notices = (f"{sum(r['notice'] for r in by['cold'])}/{args.repeats} / "
                   f"{sum(r['notice'] for r in by['warm'])}/{args.repeats}")
        lines.append(f"{command:<9}{variant:<16}{_median(by['cold'], 'seconds'):>8.2f}"
                     f"{_median(by['warm'], 'seconds'):>8.2f}{ratio:>10.1f}x{'':>3}"
                     f"{shown:<34}{notices:>19}")
    lines += ["", (f"hystkit warm (after, empty cache, every family and the control loop): "
                   f"{t_warm:.1f} s wall; the last of its lines: {warm_up}"),
              f"total {time.perf_counter() - t_total:.0f} s"]
    report = "\n".join(lines)
    print(report)
    if args.out is not None:
        args.out.write_text(report + "\n")


def _run_warm(src: Path, cwd: Path, cache: Path) -> str:
    env = {**os.environ, "PYTHONPATH": str(src), "NUMBA_CACHE_DIR": str(cache),
           "PYTHONPYCACHEPREFIX": str(cwd / "pycache")}
    done = subprocess.run([sys.executable, "-m", "hystkit", "warm"], cwd=cwd, env=env,
                          capture_output=True, text=True, check=True)
    return done.stdout.strip().splitlines()[-1]


if __name__ == "__main__":
    main()
