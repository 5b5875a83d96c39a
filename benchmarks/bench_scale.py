"""Scaling of the parallel searches and of ``hystkit batch`` (issue 13).

Run:  python benchmarks/bench_scale.py [--repeats N] [--small] [--searches-only] [--tasks]
                                      [--commands compare,generalize,...] [--out FILE]
      (writes benchmarks/last_run_scale.txt unless --out names another file)

Whole-process wall time, from starting ``python -m hystkit ...`` to its exit (what a user
waits for: start-up, reading, the work, writing), of

- ``compare`` (10 families, fit on one recording, validate on another), ``generalize`` (10
  families x the four virtual-sensor excitations) and ``select`` (every family's candidates,
  blocked time folds of one recording) at ``--workers 1`` (serial, in-process, no Dask) and
  ``--workers 2`` (Dask, two forked worker processes); issue 13 asks for >= 1.7x on 2
  cores;
- ``compare`` inside one process, split into start-up, opening the executor (Dask import,
  kernel warm-up, worker pool), the map and closing, to see where the time goes;
- the pieces of ``compare``, ``generalize`` and ``select``, timed one by one in one process
  (CPU seconds): their sum, the longest one, and what that allows on 2 workers
  (``max(longest, sum / 2)``, the critical path of a longest-first schedule's bound);
- one long fit's multi-start (Bouc-Wen, Chua and PL on 8000 samples) serially and with a
  2-worker executor open, where its starts are screened on the workers;
- one traced run of each search at 1 and 2 workers (`TRACE`): where its wall time goes, from
  the launch to the exit: start-up, imports and reading, opening the executor, the first
  piece's start, each piece on each process (``--tasks`` lists them), the idle tail, and what
  follows the map (refit, writing, exit), with the main process's CPU before, during and after;
- a fleet of 20 virtual sensors (different seeds; a fit and a validation recording each)
  through ``hystkit batch`` at 1 and 2 workers, against a shell loop that runs ``hystkit fit``
  and ``hystkit evaluate`` for each sensor (the same work: fit, model file, scores).

Paired and interleaved: every repeat runs each configuration once, the order of the two worker
counts alternating between repeats, so bursts of load hit both alike; reported are the medians
and the median of the per-repeat speed-ups. Wall and CPU time (user + system of the command
and its workers) are both given: on a shared machine the wall time carries the other jobs'
load, and CPU 1 / CPU 2 (the work the serial run does over what the parallel one does, 1.00 =
no parallel overhead) is the figure that load changes least. ``--small``: 4000-sample recordings, 8 sensors, ``generalize`` on the two recordings,
fewer select candidates (a quick check, not the issue's numbers). ``--commands compare,generalize``:
only those commands (their pieces, repeats and traces; the shell loop, the in-process breakdown
and the multi-start run only with ``batch``).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

N_SENSORS = 20

# compare in a fresh process, timed inside: start-up, opening the executor (Dask import, kernel
# warm-up, worker pool; the workers fork at the first piece), the map itself, closing. Serial
# map / (2 x parallel map) is the efficiency of the 2-worker map; what it lacks is scheduling,
# transfer and load imbalance.
BREAKDOWN = """
import json, sys, time
t0 = time.perf_counter()
from hystkit.io import read_recording
from hystkit.parallel import open_executor
from hystkit.studies import compare_models
fit, val = read_recording("fit.csv"), read_recording("val.csv")
t1 = time.perf_counter()
with open_executor(int(sys.argv[1])) as executor:
    t2 = time.perf_counter()
    compare_models(fit, val, executor=executor)
    t3 = time.perf_counter()
t4 = time.perf_counter()
print(json.dumps({"start-up": t1 - t0, "open": t2 - t1, "map": t3 - t2, "close": t4 - t3}))
"""


# Every piece of compare, generalize and select run serially in one process, each timed (CPU
# seconds of this process): which piece is the critical path of a parallel map?
PIECES = """
import json, time
from hystkit.io import read_recording
from hystkit.models import FAMILIES
from hystkit.parallel import SerialExecutor
from hystkit.models._warm import warm_kernels
from hystkit.studies import candidates, compare_models, generalization_matrix, select_model
from hystkit.sensors import simulate_experiment
from hystkit.signals import EXPERIMENTS

class Timed(SerialExecutor):
    def map(self, func, items, *, shared=None, on_done=None, cost=None):
        out = []
        for item in items:
            c0 = time.process_time()
            out.append(func(item, **(shared or {})))
            self.pieces.append((str(item)[:60], time.process_time() - c0))
        return out

warm_kernels()  # kernel loading is not a piece's work
fit, val = read_recording("fit.csv"), read_recording("val.csv")
small = SMALL
train = ({"fit": fit, "val": val} if small else
         {name: simulate_experiment(name, 1) for name in EXPERIMENTS})
test = ({"fit": fit, "val": val} if small else
        {name: simulate_experiment(name, 2) for name in EXPERIMENTS})
select_models = ["mpl", "pi", "bobbio", "chua"] if small else None  # as the commands below
runs = {"compare": lambda ex: compare_models(fit, val, executor=ex),
        "generalize": lambda ex: generalization_matrix(train, test, sorted(FAMILIES),
                                                       executor=ex),
        "select": lambda ex: select_model([fit], candidates(select_models), executor=ex)}
report = {}
for name, run in runs.items():
    if name not in ONLY:
        continue
    ex = Timed(); ex.pieces = []
    c0 = time.process_time()
    run(ex)
    total = time.process_time() - c0
    report[name] = {"pieces": ex.pieces, "outside": total - sum(s for _, s in ex.pieces)}
print(json.dumps(report))
"""

# One long fit, serially and with a 2-worker executor open (its starts on the workers): wall
# and CPU (this process and its workers). Each fit runs twice; the second is timed.
MULTISTART = """
import json, resource, sys, time
from hystkit.compensation import centre_and_scale
from hystkit.io import read_recording
from hystkit.models import get_family
from hystkit.parallel import open_executor

def cpu():
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime

rec = read_recording("fit.csv")
_, sensor, position = centre_and_scale(rec, "fit")
out = {}
def fits(tag):
    for name in ("boucwen", "chua", "pl"):
        family = get_family(name)
        structure = family.make_structure(rec.dt, family.default_size)
        family.fit(position, sensor, structure)
        t0 = time.perf_counter()
        family.fit(position, sensor, structure)
        out[f"{name} {tag}"] = time.perf_counter() - t0
if sys.argv[1] == "1":
    fits("@1")
else:
    with open_executor(2) as executor:
        fits("@2")
print(json.dumps({**out, "cpu": cpu()}))
"""


# One command run in this process, traced: wall-clock events (time.time(), comparable across
# the forked workers) appended as JSON lines to a file, each with the pid that wrote it:
# the interpreter's start (the launch time comes from the caller), the command's main(), the
# executor's opening and closing, each map and each piece (start, end, CPU), and the parent's
# own first start of a split multi-start. The workers are forked from this process after the
# patches, so they log too.
TRACE = r"""
import json, os, sys, time
from contextlib import contextmanager
T_SCRIPT = time.time()
launch, trace_file, args = float(sys.argv[1]), sys.argv[2], sys.argv[3:]
MAIN = os.getpid()
fd = os.open(trace_file, os.O_WRONLY | os.O_CREAT | os.O_APPEND)

def log(kind, label, t0, t1=None, **extra):
    os.write(fd, (json.dumps({"pid": os.getpid(), "kind": kind, "label": label, "t0": t0,
                              "t1": t1, **extra}) + "\n").encode())

log("phase", "interpreter", launch, T_SCRIPT)
from hystkit.cli import _main
if not any(os.environ.get(name) for name in _main._BLAS_THREAD_VARIABLES):
    os.environ["OPENBLAS_NUM_THREADS"] = "1"  # as the program's main() does, before numpy loads
import hystkit.identification._least_squares as least_squares
import hystkit.parallel as parallel
import hystkit.parallel._contract as executors
opened = parallel.open_executor

@contextmanager
def traced_open(*a, **k):
    t0, c0 = time.time(), time.process_time()
    with opened(*a, **k) as executor:
        if not hasattr(type(executor).map, "traced"):  # imported only now, as in a user's run
            trace_map(type(executor))
        log("phase", "open", t0, time.time(), cpu=time.process_time() - c0)
        try:
            yield executor
        finally:
            t2 = time.time()
    log("phase", "close", t2, time.time())
parallel.open_executor = traced_open

class Traced:
    def __init__(self, func):
        self.func, self.__name__ = func, getattr(func, "__name__", "piece")
    def __call__(self, item, **shared):
        t0, c0 = time.time(), time.thread_time()
        try:
            return self.func(item, **shared)
        finally:
            log("task", f"{self.__name__} {str(item)[:70]}", t0, time.time(),
                cpu=time.thread_time() - c0)

def trace_map(cls):
    run = cls.map
    def map(self, func, items, **kw):
        t0, c0 = time.time(), time.process_time()
        try:
            return run(self, Traced(func), items, **kw)
        finally:
            log("map", f"{getattr(func, '__name__', '')} x{len(items)}", t0, time.time(),
                cpu_before=c0, cpu_after=time.process_time())
    map.traced = True
    cls.map = map
trace_map(executors.SerialExecutor)
screen = least_squares._screen
def traced_screen(solve, thetas, budget):
    t0, c0 = time.time(), time.thread_time()
    try:
        return screen(solve, thetas, budget)
    finally:
        if os.getpid() == MAIN and parallel.current_executor() is not None:
            log("phase", f"multi-start of {len(thetas)} here", t0, time.time(),
                cpu=time.thread_time() - c0)
least_squares._screen = traced_screen
import contextlib, io
real_main = _main.main
def traced_main(argv=None):
    t_main = time.time()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            return real_main(argv)
    finally:
        log("phase", "main", t_main, time.time(), cpu_after=time.process_time())
_main.main = traced_main
sys.argv = ["hystkit", *args]
_main.program()  # main() on sys.argv (its GC tuning), then the program's end
"""


def _trace(cwd: Path, argv: list[str]) -> list[dict]:
    """The events of one traced run of ``hystkit ARGV`` (see `TRACE`)."""
    trace_file = cwd / "trace.jsonl"
    trace_file.unlink(missing_ok=True)
    launch = time.time()
    proc = subprocess.run([sys.executable, "-c", TRACE, str(launch), str(trace_file), *argv],
                          cwd=cwd, capture_output=True, text=True, check=False)
    end = time.time()
    if proc.returncode not in (0, 3):
        raise RuntimeError(f"traced {' '.join(argv)} failed ({proc.returncode}): {proc.stderr}")
    events = [json.loads(line) for line in trace_file.read_text().splitlines()]
    return [{"pid": None, "kind": "end", "label": "exit", "t0": end, "t1": end}, *events]


def _timeline(events: list[dict]) -> dict:
    """Where one run's wall time went, in seconds from its launch: before the main map
    (start-up, imports, reading, opening the executor), the map's first piece's latency, the
    map, each worker's busy time and idle tail, and what follows (refit, writing, exit)."""
    launch = next(e["t0"] for e in events if e["label"] == "interpreter")
    end = next(e["t0"] for e in events if e["kind"] == "end")
    main = next(e for e in events if e["label"] == "main")
    opened = next((e for e in events if e["label"] == "open"), None)
    big = max((e for e in events if e["kind"] == "map"), key=lambda e: e["t1"] - e["t0"])
    tasks = [e for e in events if e["kind"] == "task" and big["t0"] <= e["t0"] <= big["t1"]]
    workers: dict = {}
    for task in tasks:
        workers.setdefault(task["pid"], []).append(task)
    busy = {pid: sum(t["t1"] - t["t0"] for t in ts) for pid, ts in workers.items()}
    ends = [max(t["t1"] for t in ts) for ts in workers.values()]
    return {"total": end - launch, "start-up": main["t0"] - launch,
            "before map": big["t0"] - main["t0"] - (opened["t1"] - opened["t0"]
                                                   if opened else 0.0),
            "open": opened["t1"] - opened["t0"] if opened else 0.0,
            "first piece": min(t["t0"] for t in tasks) - big["t0"],
            "map": big["t1"] - big["t0"], "busy": sorted(busy.values(), reverse=True),
            "cpu": sum(t["cpu"] for t in tasks), "pieces": len(tasks),
            "tail": big["t1"] - min(ends), "after map": end - big["t1"],
            "cpu before map": big["cpu_before"], "cpu open": opened["cpu"] if opened else 0.0,
            "cpu parent in map": big["cpu_after"] - big["cpu_before"],
            "cpu after map": main["cpu_after"] - big["cpu_after"],
            "parent multi-start": sum(e["t1"] - e["t0"] for e in events
                                      if e["label"].startswith("multi-start")),
            "tasks": sorted((t["t0"] - launch, t["t1"] - launch, t["pid"], t["label"])
                             for t in events if t["kind"] == "task")}


def _machine() -> str:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"platform {platform.platform()}; cpus {os.cpu_count()}; load average {load}\n"
            f"python {platform.python_version()} ({sys.executable})")


def _python(code: str, cwd: Path, *argv: str) -> dict:
    """The JSON that `code` prints, run in a fresh Python process."""
    return json.loads(subprocess.run([sys.executable, "-c", code, *argv], cwd=cwd, check=True,
                                     capture_output=True, text=True).stdout)


def _run(argv: list[str], cwd: Path) -> tuple[float, float]:
    """Wall and CPU time (user + system of the process and the children it waited for)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode not in (0, 3):  # 3: a family or sensor failed its guards, work done
        raise RuntimeError(f"{' '.join(argv)} failed ({proc.returncode}): {proc.stderr}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _recordings(folder: Path, n_samples: int, n_sensors: int) -> None:
    from hystkit.io import Recording, write_recording
    from hystkit.sensors import simulate_experiment

    def head(rec: Recording) -> Recording:
        return Recording(time=rec.time[:n_samples], sensor=rec.sensor[:n_samples],
                         position=rec.position[:n_samples], source=rec.source)

    write_recording(head(simulate_experiment("sine", 1)), folder / "fit.csv")
    write_recording(head(simulate_experiment("sine", 2)), folder / "val.csv")
    lines = ["sensor,fit,validate"]
    for k in range(n_sensors):
        write_recording(head(simulate_experiment("sine", 100 + k)), folder / f"s{k:02d}_fit.csv")
        write_recording(head(simulate_experiment("sine", 200 + k)), folder / f"s{k:02d}_val.csv")
        lines.append(f"s{k:02d},s{k:02d}_fit.csv,s{k:02d}_val.csv")
    (folder / "fleet.csv").write_text("\n".join(lines) + "\n")
    loop = [f"for n in $(seq 0 {n_sensors - 1}); do",
            "  k=$(printf %02d $n)",
            (f"  {sys.executable} -m hystkit fit s${{k}}_fit.csv --out loop/s${{k}}.json --force"
            " > /dev/null || exit 1"),
            (f"  {sys.executable} -m hystkit evaluate loop/s${{k}}.json s${{k}}_val.csv"
            " --json loop/s${k}-scores.json --force > /dev/null || exit 1"),
            "done"]
    (folder / "loop.sh").write_text("\n".join(loop) + "\n")


def _commands(small: bool) -> dict[str, list[str]]:
    hystkit = [sys.executable, "-m", "hystkit"]
    select_models = ["--models", "mpl,pi,bobbio,chua"] if small else []
    return {
        "compare": [*hystkit, "compare", "fit.csv", "val.csv", "--out", "cmp", "--force"],
        # --small: the two recordings (2 x 2 cells a family), else the four excitations
        "generalize": [*hystkit, "generalize", *(["fit.csv", "val.csv"] if small else []),
                       "--out", "gen", "--force"],
        "select": [*hystkit, "select", "fit.csv", *select_models, "--out", "sel.json",
                   "--force"],
        "batch": [*hystkit, "batch", "fleet.csv", "--out", "fleet", "--force"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--small", action="store_true")
    parser.add_argument("--searches-only", action="store_true",
                        help="only compare, generalize and select (no shell loop, batch, "
                             "in-process breakdown or multi-start)")
    parser.add_argument("--tasks", action="store_true",
                        help="list every piece of the traced runs (start, end, process)")
    parser.add_argument("--commands", type=lambda text: text.split(","), metavar="NAMES",
                        help="only these of compare, generalize, select, batch (comma-separated; "
                             "default: all that the other options leave)")
    parser.add_argument("--out", type=Path, default=Path(__file__).with_name(
        "last_run_scale.txt"), help="also write the report here (default: %(default)s)")
    args = parser.parse_args()
    n_samples, n_sensors = (4000, 8) if args.small else (8000, N_SENSORS)
    commands = _commands(args.small)
    if args.searches_only:
        del commands["batch"]
    if args.commands:
        unknown = set(args.commands) - set(commands)
        if unknown:
            parser.error(f"--commands: unknown {', '.join(sorted(unknown))}")
        commands = {name: argv for name, argv in commands.items() if name in args.commands}
    times: dict[str, list[tuple[float, float]]] = {}
    timelines: dict[str, dict] = {}
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        (cwd / "loop").mkdir()
        _recordings(cwd, n_samples, n_sensors)
        pieces = _python(PIECES.replace("SMALL", str(args.small)).replace(
            "ONLY", repr(list(commands))), cwd)
        print("pieces timed", file=sys.stderr, flush=True)
        for repeat in range(args.repeats):
            order = ("1", "2") if repeat % 2 == 0 else ("2", "1")
            if "batch" in commands:  # the shell loop, in-process breakdown, multi-start
                times.setdefault("shell loop", []).append(_run(["bash", "loop.sh"], cwd))
                for workers in order:
                    for part, seconds in _python(BREAKDOWN, cwd, workers).items():
                        times.setdefault(f"in-process compare {part} @{workers}", []).append(
                            (seconds, 0.0))
                    fits = _python(MULTISTART, cwd, workers)
                    cpu = fits.pop("cpu")
                    for key, seconds in fits.items():
                        times.setdefault(f"multistart {key}", []).append((seconds, 0.0))
                    times.setdefault(f"multistart cpu @{workers}", []).append((cpu, 0.0))
            for name, argv in commands.items():
                for workers in order:
                    times.setdefault(f"{name} @{workers}", []).append(
                        _run([*argv, "--workers", workers], cwd))
            print(f"repeat {repeat + 1}/{args.repeats} done", file=sys.stderr, flush=True)
        for name in [name for name in commands if name != "batch"]:
            for workers in ("1", "2"):
                timelines[f"{name} @{workers}"] = _timeline(_trace(
                    cwd, [*commands[name][3:], "--workers", workers]))
        print("traced", file=sys.stderr, flush=True)
    report = _report(times, commands, args, n_samples, n_sensors, load_before, pieces)
    report += "\n\n" + _timeline_report(timelines, args.tasks)
    print(report)
    args.out.write_text(report + "\n")


def _timeline_report(timelines: dict, tasks: bool) -> str:
    """One traced run of each search at 1 and 2 workers: where its wall time went."""
    lines = [("timeline, one traced run each (wall s; start-up: interpreter and CLI; before: "
              "imports and reading; open: the executor (kernel warm-up); first: the map's first "
              "piece starts; busy: each process's pieces; tail: the map's end after the first "
              "process ran out of pieces; after: refit, writing, exit)"),
             (f"{'run':<15}{'total':>7}{'start-up':>9}{'before':>7}{'open':>6}{'first':>6}"
             f"{'map':>7}  {'busy':<12}{'tail':>5}{'after':>7}{'pieces':>7}{'CPU':>6}")]
    for run, t in timelines.items():
        busy = "/".join(f"{b:.2f}" for b in t["busy"])
        lines.append(f"{run:<15}{t['total']:>7.2f}{t['start-up']:>9.2f}{t['before map']:>7.2f}"
                     f"{t['open']:>6.2f}{t['first piece']:>6.2f}{t['map']:>7.2f}  {busy:<12}"
                     f"{t['tail']:>5.2f}{t['after map']:>7.2f}{t['pieces']:>7d}"
                     f"{t['cpu']:>6.2f}")
        lines.append(f"{'':<15}CPU of the main process: {t['cpu before map']:.2f} before the "
                     f"map (of which {t['cpu open']:.2f} opening the executor), "
                     f"{t['cpu parent in map']:.2f} during it, {t['cpu after map']:.2f} after")
        if t["parent multi-start"]:
            lines.append(f"{'':<15}(of which the parent's own first multi-start solves "
                         f"{t['parent multi-start']:.2f})")
    if tasks:
        for run, t in timelines.items():
            lines += ["", f"pieces of {run} (start, end, process):"]
            lines += [f"  {a:7.2f} {b:7.2f} {pid:>7} {label}" for a, b, pid, label in t["tasks"]]
    return "\n".join(lines)


def _report(times: dict, commands: dict, args: argparse.Namespace, n_samples: int,
            n_sensors: int, load_before: tuple, pieces: dict) -> str:
    med = {k: statistics.median(w for w, _ in v) for k, v in times.items()}
    cpu = {k: statistics.median(c for _, c in v) for k, v in times.items()}
    loads = ", ".join(f"{x:.2f}" for x in load_before)
    lines = [(f"hystkit scaling (issue 13): whole-process wall time [s], median of "
             f"{args.repeats} interleaved repeats{' (--small)' if args.small else ''}"),
             _machine() + f" (at the end; at the start {loads})",
             f"recordings of {n_samples} samples; fleet of {n_sensors} sensors", "",
             (f"{'command':<12}{'1 worker':>10}{'2 workers':>11}{'speed-up':>10}"
             f"{'(per-repeat median)':>21}{'CPU 1':>8}{'CPU 2':>8}{'CPU 1/2':>9}")]
    for name in commands:
        one, two = times[f"{name} @1"], times[f"{name} @2"]
        ratio = statistics.median(a[0] / b[0] for a, b in zip(one, two))
        lines.append(f"{name:<12}{med[f'{name} @1']:>10.2f}{med[f'{name} @2']:>11.2f}"
                     f"{med[f'{name} @1'] / med[f'{name} @2']:>9.2f}x{ratio:>20.2f}x"
                     f"{cpu[f'{name} @1']:>8.1f}{cpu[f'{name} @2']:>8.1f}"
                     f"{cpu[f'{name} @1'] / cpu[f'{name} @2']:>9.2f}")
    full = "shell loop" in med  # not --searches-only
    lines += ["", "compare in one process [s]: " + "; ".join(
        f"{part} {med[f'in-process compare {part} @1']:.2f} / "
        f"{med[f'in-process compare {part} @2']:.2f}"
        for part in ("start-up", "open", "map", "close")) + " (1 / 2 workers); map efficiency "
        f"{med['in-process compare map @1'] / (2 * med['in-process compare map @2']):.2f}"] \
        if full else []
    lines += ["", ("pieces, each timed alone in one process (CPU s): sum, longest, the bound "
              "on a 2-worker map max(longest, sum / 2), and work outside the map")]
    for name, entry in pieces.items():
        seconds = [s for _, s in entry["pieces"]]
        label, longest = max(entry["pieces"], key=lambda piece: piece[1])
        bound = max(longest, sum(seconds) / 2)
        lines.append(f"  {name:<11}{len(seconds):>3} pieces, sum {sum(seconds):6.2f}, longest "
                     f"{longest:5.2f} ({label}), bound {bound:5.2f} (at most "
                     f"{sum(seconds) / bound:.2f}x), outside {entry['outside']:5.2f}")
    if not full:
        return "\n".join(lines + ["", "all times: " + "; ".join(
            f"{k} " + ", ".join(f"{w:.2f}" for w, _ in v) for k, v in times.items())])
    fits = [k.split()[1] for k in times if k.startswith("multistart") and k.endswith("@1")
            and "cpu" not in k]
    lines += ["", "one fit on 8000 samples, wall [s] serial / 2-worker executor open (starts "
              "on the workers): " + "; ".join(
                  f"{fit} {med[f'multistart {fit} @1']:.2f} / {med[f'multistart {fit} @2']:.2f}"
                  for fit in fits) + f" (CPU of the process incl. start-up "
              f"{med['multistart cpu @1']:.1f} / {med['multistart cpu @2']:.1f})"]
    loop = med["shell loop"]
    lines += ["", (f"{n_sensors} sensors: shell loop of hystkit fit + evaluate {loop:.2f} s "
              f"(CPU {cpu['shell loop']:.1f} s, {loop / n_sensors:.2f} s per sensor); "
              f"hystkit batch {med['batch @1']:.2f} s at 1 worker "
              f"({loop / med['batch @1']:.1f}x faster), {med['batch @2']:.2f} s at 2 "
              f"({loop / med['batch @2']:.1f}x faster)"),
              "all times: " + "; ".join(f"{k} " + ", ".join(f"{w:.2f}" for w, _ in v)
                                        for k, v in times.items()
                                        if not k.startswith(("in-process", "multistart")))]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
