"""The live path's speed (issue 29, item 4): ``hystkit stream`` and ``Stream.step``, this tree
against an earlier revision, paired in one run.

Run:  python benchmarks/bench_stream.py [--before REV] [--after REV] [--rounds N] [--quick]
      [--samples N ...] [--out FILE]        (~10 min with the defaults on 2 shared cores)
      [--table3 [--models NAME ...]]        (table 3 alone, of these models, e.g. ladder_3)

Variants: ``after`` is this tree's ``src`` as it is at the start (or revision ``--after``),
``before`` revision ``--before`` (default 2bff934, checked out once with ``git worktree add
/tmp/stream_ref REV``; 'none' skips it). Every measurement runs in a child process with
``PYTHONPATH`` on the variant's ``src``, its own numba cache and bytecode folders (filled by an
untimed warm-up run). Model files are written once by the ``before`` variant (the older code:
both read its files) and shared.

1. **Command**: ``hystkit stream MODEL --in big.csv`` on each ``--samples`` count of lines
   (default 100 000 and 1 000 000: a realistic sensor file; the virtual sensor's decay run
   repeated, time continued) and on 10 lines (start-up: the interpreter, the imports, the model
   file, the kernel's cache); and the first count's lines through stdin, written by this
   process into a pipe. Wall and cpu (user + system) time per run; samples/s whole (N / wall)
   and after start-up ((N - 10) / (wall_N - wall_10)); ``same``: the outputs of the variants
   are the same text (the estimates printed with repr: bit for bit).
2. **Live**: one line written into the pipe at a time, the next only once its answer is read:
   the round trip per line (write, the command's read, parse, compensate, format, write, our
   read), median and p99 over ``--live`` lines after the first 20.
3. **In-process** (``Stream`` in the child): ``Stream.step`` per sample (p50 and p99 of each
   round's samples), ``Stream.process`` on chunks of 64 (per sample), and a plain-Python loop
   over the family's readable ``step`` on the normalised sensor (the model alone); direct
   compensators of several families fitted on the virtual sine run, and the command's model
   (mPL 1 cell with its band).

Rounds alternate the variants (A B A B ...; B A in every other round) so that bursts of load
hit both; tables give medians over rounds and the median of per-round ratios before / after.
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
FAMILIES = (("mpl", 1), ("mpl", 3), ("mpl-poly", 3), ("pi", 10), ("preisach", 20),
            ("ladder", 3))
# table 3 only (bench_export.py shares FAMILIES): the compensators that ran the Python path
# before issue 29.4 was finished, by (family, size, mode); an inverse row is NAME_SIZE_inverse
MORE_ROWS = (("bobbio", 10, "direct"), ("gpreisach", 10, "direct"), ("pi", 10, "inverse"))
CHUNK = 64
SMALL = 10


# -- the child's side: in-process latency ------------------------------------------------------

def python_latency(comp, sensor, *, repeats: int = 5, chunk: int = CHUNK) -> dict[str, float]:
    """Per-sample latency [µs] of ``Stream.step`` (median and p99), ``Stream.process`` on
    chunks of ``chunk`` samples and the plain-Python loop over the family's readable ``step``,
    medians over ``repeats`` interleaved repeats on ``sensor`` (raw sensor samples). Warms up
    (compiles) first. (``benchmarks/bench_export.py`` adds its C and MATLAB rows to these.)"""
    import numpy as np

    Stream = _stream_class()
    Stream(comp).process(sensor[:2])
    Stream(comp).step(float(sensor[0]))
    clock = time.perf_counter
    runs: dict[str, list[float]] = {"step_us": [], "step_p99_us": [], "process_chunk_us": [],
                                    "python_loop_us": []}
    for _ in range(repeats):
        stream, times = Stream(comp), np.empty(sensor.size)
        for k, v in enumerate(sensor.tolist()):
            t0 = clock()
            stream.step(v)
            times[k] = clock() - t0
        runs["step_us"].append(float(np.median(times)) * 1e6)
        runs["step_p99_us"].append(float(np.percentile(times, 99)) * 1e6)
        stream, chunks = Stream(comp), []
        for k in range(0, sensor.size - chunk + 1, chunk):
            part = sensor[k:k + chunk]
            t0 = clock()
            stream.process(part)
            chunks.append((clock() - t0) / chunk)
        runs["process_chunk_us"].append(float(np.median(chunks)) * 1e6)
        u = comp.normalised_sensor(sensor).tolist()
        # an inverse compensator runs its model's inverse step (from the state its inverse
        # reaches after the first sample: a timing loop, any reachable state does)
        inverse = getattr(comp, "mode", "direct") == "inverse"
        step = comp.family.invert_step if inverse else comp.family.step
        x = (comp.family.rest_state(comp.structure, comp.params, u[0]) if not inverse else
             comp.family.invert(comp.structure, comp.params, np.asarray(u[:1]))[1])
        loop = np.empty(len(u))
        for k, v in enumerate(u):
            t0 = clock()
            _, x = step(comp.structure, comp.params, x, v)
            loop[k] = clock() - t0
        runs["python_loop_us"].append(float(np.median(loop)) * 1e6)
    return {key: statistics.median(values) for key, values in runs.items()}


def _latency(models: Path, n_samples: int) -> dict:
    """`python_latency` (one repeat) of every model file in `models`, on `n_samples` of the
    virtual sensor's decay run (seed 2); and whether the stream ran compiled."""
    from hystkit.compensation import load_compensator
    from hystkit.sensors import simulate_experiment

    Stream = _stream_class()

    sensor = simulate_experiment("decay", 2).sensor[:n_samples]
    found = {}
    for path in sorted(models.glob("*.json")):
        comp = load_compensator(path)
        found[path.stem] = {**python_latency(comp, sensor, repeats=1),
                            "compiled": getattr(Stream(comp), "compiled", None)}
    return found


def _stream_class():
    """``Stream`` from ``hystkit.live``, or (revisions before the live package) from
    ``hystkit.compensation``."""
    try:
        from hystkit.live import Stream
    except ImportError:
        from hystkit.compensation import Stream
    return Stream


def _make_models(folder: Path, names: list[str] | None = None, command: bool = True) -> None:
    """The in-process table's compensators (direct, no band; of `names` only if given) and
    the command's model (unless not `command`)."""
    from hystkit.cli import main as cli
    from hystkit.compensation import fit_compensator, save_compensator
    from hystkit.io import write_recording
    from hystkit.sensors import simulate_experiment

    train = simulate_experiment("sine", 1)
    models = folder / "models"
    models.mkdir()
    for name, size, mode in [(*row, "direct") for row in FAMILIES] + list(MORE_ROWS):
        label = f"{name}_{size}" + ("_inverse" if mode == "inverse" else "")
        if names and label not in names:
            continue
        comp = fit_compensator(train, size, model=name, mode=mode, diagnose=False)
        save_compensator(comp, models / f"{label}.json")
    if not command:
        return
    write_recording(train, folder / "train.csv")
    code = cli(["fit", str(folder / "train.csv"), "--cells", "1", "--out",
                str(models / "command_mpl_1_band.json")])
    assert code == 0, code


# -- the parent's side -------------------------------------------------------------------------

WORKTREE = Path("/tmp/stream_ref")


def _source(rev: str, folder: Path) -> Path:
    """The ``src`` of this tree ('tree', copied into `folder` as it is now) or of revision
    `rev` (a git worktree at ``WORKTREE``, added once and kept at `rev`)."""
    if rev == "tree":
        shutil.copytree(REPO / "src", folder / "src",
                        ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        return folder / "src"
    if not WORKTREE.exists():
        subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(WORKTREE),
                        rev], capture_output=True, check=True)
    subprocess.run(["git", "-C", str(WORKTREE), "checkout", "--quiet", "--detach", rev],
                   check=True)
    return WORKTREE / "src"


class Variant:
    """A source tree and the environment of its children."""

    def __init__(self, name: str, rev: str, tmp: Path) -> None:
        self.name, self.rev = name, rev
        root = tmp / name
        self.src = _source(rev, root)
        self.env = {**os.environ, "PYTHONPATH": str(self.src),
                    "NUMBA_CACHE_DIR": str(root / "numba"),
                    "PYTHONPYCACHEPREFIX": str(root / "pycache"), "OPENBLAS_NUM_THREADS": "1"}
        self.env.pop("PYTHONDONTWRITEBYTECODE", None)

    def python(self, args: list[str], **run) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, *args], env=self.env, check=True, **run)

    def stream(self, model: Path, data: Path | None, text: bytes | None = None
               ) -> tuple[float, bytes, float]:
        """Wall seconds of ``hystkit stream`` on a file (or stdin fed `text`), its stdout,
        its cpu seconds (user + system)."""
        args = ["-m", "hystkit", "stream", str(model)] + ([] if data is None
                                                          else ["--in", str(data)])
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        done = self.python(args, input=text, capture_output=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        return wall, done.stdout, cpu

    def live(self, model: Path, lines: list[bytes]) -> list[float]:
        """Round trip [s] of each line written alone, its answer read before the next."""
        proc = subprocess.Popen([sys.executable, "-m", "hystkit", "stream", str(model)],
                                env=self.env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, bufsize=0)
        assert proc.stdin is not None and proc.stdout is not None
        out = proc.stdout
        _read_line(out)  # the header: the command is ready
        trips = []
        for line in lines:
            t0 = time.perf_counter()
            proc.stdin.write(line)
            _read_line(out)
            trips.append(time.perf_counter() - t0)
        proc.stdin.close()
        proc.wait()
        return trips


def _read_line(stream) -> bytes:
    line = b""
    while not line.endswith(b"\n"):
        byte = os.read(stream.fileno(), 1)
        if not byte:
            raise RuntimeError(f"the stream's output ended mid-line: {line!r}")
        line += byte
    return line


def _data(folder: Path, counts: list[int]) -> tuple[dict[int, Path], Path]:
    """Files of each count and of SMALL lines of the decay run (seed 2) repeated, time
    continued, as CSV."""
    import numpy as np

    from hystkit.sensors import simulate_experiment

    rec = simulate_experiment("decay", 2)
    n = max(counts)
    sensor = np.tile(rec.sensor, -(-n // rec.n_samples))[:n]
    time_s = np.arange(n) * rec.dt
    rows = [f"{t!r},{s!r}\n" for t, s in zip(time_s.tolist(), sensor.tolist(), strict=True)]
    files = {}
    for count in counts:
        files[count] = folder / f"big_{count}.csv"
        files[count].write_text("time,sensor\n" + "".join(rows[:count]))
    small = folder / "small.csv"
    small.write_text("time,sensor\n" + "".join(rows[:SMALL]))
    return files, small


def _median(values: list[float]) -> float:
    return statistics.median(values) if values else float("nan")


def _ratio(pairs: list[tuple[float, float]]) -> str:
    return f"{statistics.median(b / a for a, b in pairs):.2f}" if pairs else "-"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--before", default="2bff934", metavar="REV",
                        help="git revision to compare with ('none': this tree alone)")
    parser.add_argument("--after", default="tree", metavar="REV",
                        help="git revision to measure (default: this tree as it is)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--samples", type=int, nargs="+", default=[100_000, 1_000_000])
    parser.add_argument("--live", type=int, default=2000, help="lines of the live table")
    parser.add_argument("--quick", action="store_true", help="20 000 samples, 2 rounds")
    parser.add_argument("--out", type=Path, help="also write the report here")
    parser.add_argument("--latency-child", nargs=2, metavar=("MODELS", "N"),
                        help=argparse.SUPPRESS)
    parser.add_argument("--models-child", metavar="FOLDER", help=argparse.SUPPRESS)
    parser.add_argument("--table3", action="store_true",
                        help="only table 3 (in-process Stream.step), no command runs")
    parser.add_argument("--models", nargs="+", metavar="NAME",
                        help="table 3's models, e.g. ladder_3 mpl_3 (default: all)")
    args = parser.parse_args()
    if args.latency_child:
        print(json.dumps(_latency(Path(args.latency_child[0]), int(args.latency_child[1]))))
        return
    if args.models_child:
        _make_models(Path(args.models_child), args.models, command=not args.table3)
        return
    if args.quick:
        args.samples, args.rounds, args.live = [20_000], 2, 500
    report = _run(args)
    print(report)
    if args.out:
        args.out.write_text(report + "\n", encoding="utf-8")


def _run(args: argparse.Namespace) -> str:
    t_start = time.perf_counter()
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    lines = [(f"hystkit stream and Stream.step: medians of {args.rounds} rounds, variants "
             f"alternating (A B, B A, ...)"),
             (f"machine: {platform.platform()}; {os.cpu_count()} cpus; load {load} at start; "
             f"python {platform.python_version()}")]
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        variants = [Variant("after", args.after, tmp)]
        if args.before != "none":
            variants.insert(0, Variant("before", args.before, tmp))
        lines.append("variants: " + "; ".join(f"{v.name} = {v.rev}" for v in variants))
        selection = (["--models", *args.models] if args.models else []) + \
            (["--table3"] if args.table3 else [])
        variants[0].python([__file__, "--models-child", str(tmp), *selection],
                           capture_output=True)
        models = tmp / "models"
        if args.table3:
            lines += _table3_only(args, variants, models)
            lines.append(f"load at the end {', '.join(f'{x:.2f}' for x in os.getloadavg())}; "
                         f"benchmark {time.perf_counter() - t_start:.0f} s")
            return "\n".join(lines)
        model = models / "command_mpl_1_band.json"
        files, small = _data(tmp, args.samples)
        text = files[args.samples[0]].read_bytes()
        live_lines = [line + b"\n" for line in
                      text.splitlines()[1:args.live + 21]]
        for v in variants:  # warm-up: compile or load every kernel once, untimed
            v.stream(model, small)
            v.python([__file__, "--latency-child", str(models), "50"], capture_output=True)
        runs: dict[str, dict[str, list]] = {v.name: {} for v in variants}
        outputs: dict[str, dict[int, set[bytes]]] = {v.name: {} for v in variants}
        for r in range(args.rounds):
            for v in (variants if r % 2 == 0 else variants[::-1]):
                row = runs[v.name]
                for count, big in files.items():
                    seconds, out, cpu = v.stream(model, big)
                    outputs[v.name].setdefault(count, set()).add(out)
                    row.setdefault(("file", count), []).append(seconds)
                    row.setdefault(("cpu", count), []).append(cpu)
                seconds, _, cpu = v.stream(model, small)
                row.setdefault("small", []).append(seconds)
                row.setdefault("small cpu", []).append(cpu)
                seconds, out, _ = v.stream(model, None, text)
                outputs[v.name].setdefault(args.samples[0], set()).add(out)
                row.setdefault("stdin", []).append(seconds)
                if r < 3:
                    row.setdefault("live", []).append(v.live(model, live_lines)[20:])
                found = json.loads(v.python([__file__, "--latency-child", str(models),
                                             "2000"], capture_output=True, text=True).stdout)
                row.setdefault("latency", []).append(found)
        lines += _tables(args, variants, runs, outputs)
    lines.append(f"load at the end {', '.join(f'{x:.2f}' for x in os.getloadavg())}; "
                 f"benchmark {time.perf_counter() - t_start:.0f} s")
    return "\n".join(lines)


def _tables(args, variants, runs, outputs) -> list[str]:
    import numpy as np

    names = [v.name for v in variants]
    same = all(len(set().union(*(o[n] for o in outputs.values()))) == 1 for n in args.samples)
    lines = ["", (f"Table 1. hystkit stream, mPL 1 cell with its band, --in FILE of N samples "
                 f"(and {SMALL}: start-up), stdin: the first N through a pipe; wall seconds, "
                 f"cpu seconds (user + system), samples/s; outputs the same text in every run "
                 f"and variant: {same}"),
             (f"  {'N':>8} {'variant':<7} {'wall s':>7} {'cpu s':>6} {'start-up s':>10} "
              f"{'whole /s':>9} {'after start /s':>14} {'cpu /s':>9} {'stdin whole /s':>14}")]
    for n in args.samples:
        for name in names:
            row = runs[name]
            file_s, cpu_s = _median(row[("file", n)]), _median(row[("cpu", n)])
            small_s = _median(row["small"])
            steady = [(n - SMALL) / (f - s) for f, s in zip(row[("file", n)], row["small"],
                                                            strict=True)]
            stdin = f"{args.samples[0] / _median(row['stdin']):>14.0f}" \
                if n == args.samples[0] else f"{'':>14}"
            lines.append(f"  {n:>8} {name:<7} {file_s:>7.2f} {cpu_s:>6.2f} {small_s:>10.2f} "
                         f"{n / file_s:>9.0f} {_median(steady):>14.0f} {n / cpu_s:>9.0f} "
                         f"{stdin}")
        if len(names) == 2:
            wall = list(zip(runs["after"][("file", n)], runs["before"][("file", n)],
                            strict=True))
            cpu = list(zip(runs["after"][("cpu", n)], runs["before"][("cpu", n)], strict=True))
            lines.append(f"  {n:>8} before / after (median of paired rounds): wall "
                         f"{_ratio(wall)}, cpu {_ratio(cpu)}")
    lines.append("  start-up cpu s (10 lines): " + ", ".join(
        f"{name} {_median(runs[name]['small cpu']):.2f}" for name in names))
    lines += ["", (f"Table 2. live: one line at a time through a pipe, its answer read before "
                  f"the next; round trip per line [µs] over {args.live} lines"),
              f"  {'variant':<8} {'median':>8} {'p99':>8}"]
    for name in names:
        trips = np.concatenate(runs[name]["live"]) * 1e6
        lines.append(f"  {name:<8} {np.median(trips):>8.1f} {np.percentile(trips, 99):>8.1f}")
    return lines + _latency_table(names, runs)


def _table3_only(args, variants, models: Path) -> list[str]:
    """Table 3 alone: the latency child of each variant, rounds alternating as in `_run`."""
    for v in variants:  # warm-up: compile or load every kernel once, untimed
        v.python([__file__, "--latency-child", str(models), "50"], capture_output=True)
    runs: dict[str, dict[str, list]] = {v.name: {"latency": []} for v in variants}
    for r in range(args.rounds):
        for v in (variants if r % 2 == 0 else variants[::-1]):
            found = json.loads(v.python([__file__, "--latency-child", str(models), "2000"],
                                        capture_output=True, text=True).stdout)
            runs[v.name]["latency"].append(found)
    return _latency_table([v.name for v in variants], runs)


def _latency_table(names: list[str], runs) -> list[str]:
    lines = ["", ("Table 3. in-process, µs per sample (2000 samples of the decay run; "
                  "compensators fitted on the sine run, direct unless _inverse): Stream.step p50 / p99, "
                  "Stream.process on chunks of 64, a plain-Python loop over the family's step"),
              (f"  {'model':<22} {'variant':<7} {'compiled':>8} {'step p50':>9} "
              f"{'step p99':>9} {'process/64':>11} {'python loop':>12} {'step / loop':>12}")]
    for model in runs[names[-1]]["latency"][0]:
        for name in names:
            rounds = [found[model] for found in runs[name]["latency"]]
            step = _median([f["step_us"] for f in rounds])
            loop = _median([f["python_loop_us"] for f in rounds])
            lines.append(f"  {model:<22} {name:<7} {rounds[0]['compiled']!s:>8} {step:>9.2f} "
                         f"{_median([f['step_p99_us'] for f in rounds]):>9.2f} "
                         f"{_median([f['process_chunk_us'] for f in rounds]):>11.2f} "
                         f"{loop:>12.2f} {step / loop:>12.3f}")
        if len(names) == 2:
            pairs = [(a[model]["step_us"], b[model]["step_us"]) for a, b in
                     zip(runs["after"]["latency"], runs["before"]["latency"], strict=True)]
            lines.append(f"  {model:<22} before / after, step p50: {_ratio(pairs)}")
    return lines


if __name__ == "__main__":
    main()
