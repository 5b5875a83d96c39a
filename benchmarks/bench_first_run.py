"""The first run after installing against a later one: numba's cache empty vs filled (issue 29).

Run:  python benchmarks/bench_first_run.py [--repeats N] [--before REV] [--after REV|SRC]
      [--commands fit,control] [--compare] [--in-process ROUNDS] [--no-warm-command]
      [--out FILE]     (~6 min with the defaults on 2 cores; --compare adds ~4 min)

Whole-process wall time of ``python -m hystkit ...`` in a temporary folder, on the virtual
sensor's noise recording (seed 1, 8000 samples at 40 Hz) to fit and its sine recording (seed
2) to validate:

- ``fit DATA --model mpl --out M.json`` (1 mPL cell) and ``control --scheme direct
  --experiment sine``; with ``--compare`` also ``compare FIT VAL`` (every family);
- *cold*: ``NUMBA_CACHE_DIR`` a fresh empty folder, as after installing (every kernel the
  command needs is compiled); *warm*: a folder that a run of the same command filled before
  (untimed), as every later run;
- for this tree (``after``, its ``src`` copied as it is at the start; ``--after``: a git
  revision's or another ``src`` folder, e.g. a worktree holding only the change to judge) and for the source of
  git revision REV (``--before``, ``git archive`` into a temporary folder; default 12c336a, the commit before issue 29's
  caching: the control loop was compiled by every process and ``fit_seconds`` held the
  compilation). Children run with ``PYTHONPATH`` on the variant's ``src`` and Python's
  bytecode cache in a temporary ``PYTHONPYCACHEPREFIX`` (filled by the untimed warm-up run).

Wall time and CPU time (the child's user + system) of each run.
Paired and interleaved: each repeat runs, for every command, the variants cold one after the
other, then warm (after before, before after in the next repeat: A B B A ...), so bursts of
the machine's load hit all alike; reported are the medians and the median of the per-repeat
cold / warm ratios and of the per-repeat after / before ratios. Beside the times: the model
file's ``fit_seconds`` (the fit alone, not the compilation, since issue 29), control's
``compile_seconds`` (compiling or loading its loop kernel) and whether the program's
one-line compilation notice was on stderr. ``--in-process ROUNDS``: the warm fit without
the process around it, ``fit_compensator`` (1 mPL cell) timed in a child per variant (median
of 15 fits after one untimed), ROUNDS rounds A B B A. Last, one cold ``hystkit warm`` (after
only; ``--no-warm-command`` skips it).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
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
    "fit": ["fit", "fit.csv", "--model", "mpl", "--out", "model.json", "--force"],
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


def _source(variant: str, rev: str | None, tmp: Path) -> Path:
    """The ``src`` folder of `variant`, copied into `tmp`: this tree's as it is (`rev` None; so
    that edits during the run do not invalidate the cache), a ``src`` folder's (`rev` an
    existing folder), or revision `rev`'s."""
    folder = tmp / f"src-{variant}"
    if rev is None or Path(rev).is_dir():
        shutil.copytree(REPO / "src" if rev is None else Path(rev), folder / "src",
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
    t0, cpu0 = time.perf_counter(), _children_cpu()
    done = subprocess.run([sys.executable, "-m", "hystkit", *COMMANDS[command]], cwd=cwd,
                          env=env, capture_output=True, text=True, check=False)
    seconds, cpu = time.perf_counter() - t0, _children_cpu() - cpu0
    if done.returncode not in (0, 3):
        raise RuntimeError(f"{command} exited {done.returncode}: {done.stderr[-500:]}")
    row = {"seconds": seconds, "cpu": cpu, "notice": NOTICE in done.stderr}
    if command == "fit":
        row["inner"] = _found(json.loads((cwd / "model.json").read_text()), "fit_seconds")
    elif command == "control":
        row["inner"] = _found(json.loads((cwd / "ctl" / "metrics.json").read_text()),
                              "compile_seconds")
    return row


def _children_cpu() -> float:
    """User + system CPU seconds of the finished children (runs are one at a time)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


IN_PROCESS = """
import statistics, sys, time
from hystkit.compensation import fit_compensator
from hystkit.io import read_recording
recording = read_recording(sys.argv[1])
fit_compensator(recording, 1, model="mpl")  # loads the kernels (warm cache)
times = []
for _ in range(15):
    t0 = time.perf_counter()
    fit_compensator(recording, 1, model="mpl")
    times.append(time.perf_counter() - t0)
print(statistics.median(times))
"""


def _in_process(src: Path, cwd: Path, cache: Path) -> float:
    """Median seconds of a warm in-process ``fit_compensator`` (1 mPL cell) of `src`."""
    env = {**os.environ, "PYTHONPATH": str(src), "NUMBA_CACHE_DIR": str(cache),
           "PYTHONPYCACHEPREFIX": str(cwd / "pycache")}
    done = subprocess.run([sys.executable, "-c", IN_PROCESS, "fit.csv"], cwd=cwd, env=env,
                          capture_output=True, text=True, check=True)
    return float(done.stdout.split()[-1])


def _ratio(after: list[dict], before: list[dict], key: str) -> str:
    """Median and range of the per-repeat after / before ratios of `key`."""
    ratios = sorted(a[key] / b[key] for a, b in zip(after, before, strict=True))
    return f"{statistics.median(ratios):.2f} ({ratios[0]:.2f}-{ratios[-1]:.2f})"


def _median(rows: list[dict], key: str) -> float | None:
    values = [r[key] for r in rows if r.get(key) is not None]
    return statistics.median(values) if values else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--before", default=BEFORE, metavar="REV",
                        help=f"git revision to compare with (default {BEFORE}; 'none': skip)")
    parser.add_argument("--after", default=None, metavar="REV|SRC",
                        help="the variant to judge: a git revision or a src folder (default: "
                             "this tree's src)")
    parser.add_argument("--commands", default="fit,control",
                        help="commands to time, of fit, control (default both)")
    parser.add_argument("--compare", action="store_true", help="also time `hystkit compare`")
    parser.add_argument("--in-process", type=int, default=0, metavar="ROUNDS",
                        help="also time a warm in-process fit_compensator, ROUNDS rounds")
    parser.add_argument("--no-warm-command", action="store_true",
                        help="skip the cold `hystkit warm` at the end")
    parser.add_argument("--out", type=Path, default=None,
                        help="also write the report here (benchmarks/last_run_first_run.txt)")
    args = parser.parse_args()
    from hystkit.io import write_recording
    from hystkit.sensors import simulate_experiment

    commands = args.commands.split(",") + (["compare"] if args.compare else [])
    variants = ["after"] + ([] if args.before == "none" else [f"before {args.before}"])
    title = (f"hystkit's first run with numba's cache empty (cold) vs filled (warm): "
             f"whole-process wall time [s], medians of {args.repeats} interleaved repeats")
    lines = [title, _machine(), ""]
    t_total = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        write_recording(simulate_experiment("noise", 1), tmp / "fit.csv")
        write_recording(simulate_experiment("sine", 2), tmp / "val.csv")
        srcs = {v: _source(v.split()[0], args.after if v == "after" else args.before, tmp)
                for v in variants}
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
        in_process: dict = {v: [] for v in variants}
        for repeat in range(args.in_process):
            for variant in variants if repeat % 2 == 0 else variants[::-1]:
                in_process[variant].append(_in_process(srcs[variant], tmp, warm[variant, "fit"]))
        t_warm = time.perf_counter()
        warm_up = (None if args.no_warm_command else
                   _run_warm(srcs["after"], tmp, tmp / "cold-warm-command"))
        t_warm = time.perf_counter() - t_warm
    inner = {"fit": "fit_seconds", "control": "loop compile s", "compare": ""}
    lines.append(f"{'command':<9}{'variant':<16}{'cold s':>8}{'cpu':>7}{'warm s':>8}{'cpu':>7}"
                 f"{'cold/warm':>11}{'':>3}{'inner: cold / warm':<34}{'notice cold / warm':>19}")
    for (variant, command), by in rows.items():
        ratio = statistics.median(c["seconds"] / w["seconds"]
                                  for c, w in zip(by["cold"], by["warm"], strict=True))
        cold_inner, warm_inner = _median(by["cold"], "inner"), _median(by["warm"], "inner")
        shown = (f"{inner[command]} {cold_inner:.3f} / {warm_inner:.3f}"
                 if cold_inner is not None else "")
        notices = (f"{sum(r['notice'] for r in by['cold'])}/{args.repeats} / "
                   f"{sum(r['notice'] for r in by['warm'])}/{args.repeats}")
        lines.append(f"{command:<9}{variant:<16}{_median(by['cold'], 'seconds'):>8.2f}"
                     f"{_median(by['cold'], 'cpu'):>7.2f}{_median(by['warm'], 'seconds'):>8.2f}"
                     f"{_median(by['warm'], 'cpu'):>7.2f}{ratio:>10.1f}x{'':>3}"
                     f"{shown:<34}{notices:>19}")
    if len(variants) == 2:
        lines += ["", f"after / {variants[1]}, medians of the per-repeat ratios (paired):"]
        for command in commands:
            shown = []
            for state in ("cold", "warm"):
                for key in ("seconds", "cpu"):
                    shown.append(f"{state} {'wall' if key == 'seconds' else 'cpu'} " + _ratio(
                        rows["after", command][state], rows[variants[1], command][state], key))
            lines.append(f"  {command}: " + ", ".join(shown))
    if args.in_process:
        lines += ["", (f"warm in-process fit_compensator (1 mPL cell), median of 15 fits per "
                       f"child, {args.in_process} rounds:")]
        for variant, times in in_process.items():
            lines.append(f"  {variant:<16} median {statistics.median(times) * 1e3:.2f} ms "
                         f"(rounds {', '.join(f'{t * 1e3:.2f}' for t in times)})")
        if len(variants) == 2:
            ratios = [a / b for a, b in zip(*in_process.values(), strict=True)]
            lines.append(f"  after / before: median {statistics.median(ratios):.3f} "
                         f"(rounds {', '.join(f'{r:.3f}' for r in ratios)})")
    if warm_up is not None:
        lines += ["", (f"hystkit warm (after, empty cache, every family and the control loop): "
                       f"{t_warm:.1f} s wall; the last of its lines: {warm_up}")]
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    lines.append(f"load average at the end {load}; total {time.perf_counter() - t_total:.0f} s")
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
