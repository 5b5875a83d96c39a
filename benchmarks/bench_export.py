"""Footprint and speed of the exported compensators, beside the Python stream.

Run:  python benchmarks/bench_export.py [--quick]     (writes benchmarks/last_run_export.txt)
      python benchmarks/bench_export.py --octave [--before REV] [--rounds N] [--samples N]
            [--families NAME ...] [--out FILE]
            (the Octave table alone; appends a dated section to benchmarks/last_run_export.txt)

Compensators are fitted (direct mode, centring fit) on the virtual sensor's sine run, as in
``bench_stream.py``, and exported with ``hystkit.export``. Per family:

- ``state B``: ``sizeof(NAME_state)`` in float / double (model state, centring, flags);
- ``step B``: size of the compiled ``NAME_step`` symbol (``nm -S``; the family's model code is
  inlined into it) and ``.text`` of the whole object (``size``; init, sync and step), float,
  ``cc -O2 -std=c99``, this machine (x86-64; a Cortex-M build is smaller or larger by the ISA);
- ``C ns``: nanoseconds per sample, float / double: ``NAME_step`` over 1e6 samples (the decay
  run's 8000 sensor samples 125 times, the state carried on), median of interleaved repeats
  (every repeat runs every family once, so load bursts hit all alike);
- ``octave µs``: the MATLAB export in GNU Octave, ``NAME(sensor)`` on 2000 samples, per sample;
- Python rows from ``bench_stream.python_latency``: ``Stream.step``, ``Stream.process`` on
  chunks of 64, and the family's readable ``step`` in a plain-Python loop (µs per sample).

``--octave``: the MATLAB export of every exported family and mode (:data:`OCTAVE_CASES`, the
export tests' sizes, centring fit, fitted on the sine run) in GNU Octave, the code written by
revision ``--before`` (``git archive``; its ``src`` in a child process) against this tree's,
paired: one Octave process, ``NAME(sensor)`` on the first ``--samples`` of the noise run (seed
2, the export tests' recording) per round, the variants alternating (A B, then B A). CPU time
(Octave's ``cputime``) per sample, medians over rounds, and the median of per-round ratios
before / after; ``max |diff|`` is the largest difference of the two variants' estimates [mm].
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from hystkit.compensation import (
    Compensator,
    LinearBaseline,
    fit_compensator,
    load_compensator,
    prepare_training_data,
    save_compensator,
)
from hystkit.errors import HystkitError
from hystkit.export import c_files, make_plan, matlab_files
from hystkit.models import get_family
from hystkit.sensors import simulate_experiment

sys.path.insert(0, str(Path(__file__).parent))
from bench_stream import FAMILIES, python_latency

HERE = Path(__file__).parent
N_LOOP = 1_000_000
# (family, size) of the Octave table: tests/export's cases (mpl-g: tests/models'), both modes
OCTAVE_CASES = (("mpl", 1), ("mpl", 3), ("mpl-poly", 1), ("mpl-g", 2), ("pi", 6),
                ("preisach", 12), ("gpreisach", 10), ("ladder", 3), ("boucwen", 1),
                ("bobbio", 6), ("chua", 2), ("pl", 2))

_TIMER = r"""#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "comp.h"
#define N_MAX 8000
static comp_real data[N_MAX];
int main(int argc, char **argv)
{
    FILE *f = fopen(argv[1], "r");
    long n = 0, k, total = atol(argv[2]);
    double v, check = 0.0;
    comp_state st;
    struct timespec t0, t1;
    (void)argc;
    while (n < N_MAX && fscanf(f, "%lf", &v) == 1) data[n++] = (comp_real)v;
    fclose(f);
    comp_init(&st, data[0]);
    for (k = 0; k < n; k++) check += comp_step(&st, data[k]);  /* warm the caches */
    comp_init(&st, data[0]);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (k = 0; k < total; k++) check += comp_step(&st, data[k % n]);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("%zu %.3f %g\n", sizeof(comp_state),
           ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / total, check);
    return 0;
}
"""


def _build(comp, folder: Path, double: bool) -> dict:
    folder.mkdir(parents=True)
    for name, text in c_files(make_plan(comp, "comp"), double).items():
        if name != "example_main.c":
            (folder / name).write_text(text)
    (folder / "timer.c").write_text(_TIMER)
    cc = ["cc", "-O2", "-std=c99"]
    subprocess.run([*cc, "-c", "comp.c"], cwd=folder, check=True)
    subprocess.run([*cc, "comp.c", "timer.c", "-lm", "-o", "timer"], cwd=folder, check=True)
    text = int(subprocess.run(["size", "comp.o"], cwd=folder, check=True, capture_output=True,
                              text=True).stdout.splitlines()[1].split()[0])
    step = 0
    for line in subprocess.run(["nm", "-S", "comp.o"], cwd=folder, check=True,
                               capture_output=True, text=True).stdout.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[3] == "comp_step":
            step = int(parts[1], 16)
    return {"timer": folder / "timer", "text": text, "step": step}


def _time(binary: Path, data: Path, n: int) -> tuple[int, float]:
    out = subprocess.run([str(binary), str(data), str(n)], check=True, capture_output=True,
                         text=True).stdout.split()
    return int(out[0]), float(out[1])


def _octave_us(comp, folder: Path, data: Path, n: int) -> float | None:
    if shutil.which("octave") is None:
        return None
    folder.mkdir(parents=True)
    for name, text in matlab_files(make_plan(comp, "comp")).items():
        (folder / name).write_text(text)
    script = (f"cd('{folder}'); s = load('{data}'); s = s(1:{n}); comp(s(1:10)); tic; "
              f"comp(s); printf('%.6f\\n', toc / {n});")
    out = subprocess.run(["octave", "--no-gui", "--quiet", "--eval", script], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[-1]) * 1e6


def _octave_compensator(fit_rec, use_rec, name: str, size: int, mode: str):
    """Fitted (centring fit); where the fit fails or diverges on ``use_rec``, the first draw
    of the family's documented domain (seed 0, 1, ...) that stays finite, on the fit's
    conventions (as the export tests' ``build_compensator``); None if neither."""
    try:
        comp = fit_compensator(fit_rec, size, model=name, mode=mode, center="fit",
                               diagnose=False)
        comp.estimate(use_rec)
        return comp
    except HystkitError:
        pass
    conventions, s, _ = prepare_training_data([fit_rec], "fit")
    family = get_family(name)
    structure = family.make_structure(fit_rec.dt, size)
    for seed in range(40):
        try:
            comp = Compensator(
                structure=structure, mode=mode, center="fit", model=name,
                params=family.random_params(structure, np.random.default_rng(seed)),
                baseline=LinearBaseline(1.0, 0.0),
                training_range=(float(np.min(s[0])), float(np.max(s[0]))),
                position_range=(float(np.min(fit_rec.position)),
                                float(np.max(fit_rec.position))), **conventions)
            comp.estimate(use_rec)
        except (HystkitError, ValueError):
            continue
        return comp
    return None


def _write_matlab_child(models: Path, out: Path, prefix: str) -> None:
    """In the variant's interpreter: every model file's MATLAB export, named PREFIX_STEM."""
    for path in sorted(models.glob("*.json")):
        for file, text in matlab_files(make_plan(load_compensator(path),
                                                 f"{prefix}_{path.stem}")).items():
            (out / file).write_text(text)


def _octave_table(args: argparse.Namespace) -> list[str]:
    if shutil.which("octave") is None:
        raise SystemExit("--octave: GNU Octave is not installed")
    fit_rec, use_rec = simulate_experiment("sine", 1), simulate_experiment("noise", 2)
    n = args.samples
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        models, code = tmp / "models", tmp / "m"
        models.mkdir()
        code.mkdir()
        labels = []
        for name, size in OCTAVE_CASES:
            if args.families and name not in args.families:
                continue
            family = get_family(name)
            inverse = family.invert is not None and family.export.inverse
            for mode in ("direct", "inverse") if inverse else ("direct",):
                size_here = 1 if (name, mode) == ("mpl-g", "inverse") else size
                comp = _octave_compensator(fit_rec, use_rec, name, size_here, mode)
                label = f"{name.replace('-', '_')}_{size_here}_{mode}"
                if comp is None:
                    print(f"{label}: no usable compensator, skipped", flush=True)
                    continue
                save_compensator(comp, models / f"{label}.json")
                labels.append(label)
        before_src = tmp / "before"
        before_src.mkdir()
        archive = subprocess.run(["git", "archive", args.before, "src"], cwd=HERE.parent,
                                 check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(before_src)], input=archive, check=True)
        variants = {"before": before_src / "src", "after": HERE.parent / "src"}
        for prefix, src in variants.items():
            env = {**os.environ, "PYTHONPATH": str(src)}
            subprocess.run([sys.executable, __file__, "--write-matlab-child", str(models),
                            str(code), prefix], env=env, check=True)
        data = tmp / "sensor.txt"
        np.savetxt(data, use_rec.sensor[:n], fmt="%.17g")
        script = [f"cd('{code}'); s = load('{data}');"]
        script += [f"{prefix}_{label}(s(1:10));" for label in labels for prefix in variants]
        for r in range(args.rounds):  # round 0 also writes each variant's estimates
            order = list(variants) if r % 2 == 0 else list(variants)[::-1]
            for label in labels:
                for prefix in order:
                    fn = f"{prefix}_{label}"
                    script.append(f"t0 = cputime; e = {fn}(s); t = cputime - t0; "
                                  f"printf('T {r} {label} {prefix} %.9g\\n', t);")
                    if r == 0:
                        script.append(f"fid = fopen('{fn}.out', 'w'); "
                                      "fprintf(fid, '%.17g\\n', e); fclose(fid);")
        run = subprocess.run(["octave", "--no-gui", "--quiet", "--no-window-system", "--eval",
                              "\n".join(script)], check=False, capture_output=True, text=True)
        if run.returncode != 0:
            raise SystemExit(f"octave failed: {run.stderr.strip()[-2000:]}")
        cpu: dict = {}
        for line in run.stdout.splitlines():
            if line.startswith("T "):
                _, r, label, prefix, t = line.split()
                cpu.setdefault(label, {}).setdefault(prefix, []).append(float(t) / n * 1e6)
        lines = [(f"{'model, mode':<26} {'before µs':>10} {'after µs':>9} {'ratio':>7} "
                  f"{'max |diff| mm':>14}")]
        for label in labels:
            b, a = cpu[label]["before"], cpu[label]["after"]
            diff = np.max(np.abs(np.loadtxt(code / f"before_{label}.out")
                                 - np.loadtxt(code / f"after_{label}.out")))
            ratio = statistics.median(x / y for x, y in zip(b, a, strict=True))
            lines.append(f"{label:<26} {statistics.median(b):>10.1f} "
                         f"{statistics.median(a):>9.1f} {ratio:>7.2f} {diff:>14.3g}")
            print(lines[-1], flush=True)
    return lines


def _octave_main(args: argparse.Namespace) -> None:
    version = subprocess.run(["octave", "--version"], check=True, capture_output=True,
                             text=True).stdout.splitlines()[0]
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    git = ["git", "-C", str(HERE.parent)]
    head_rev = subprocess.run([*git, "rev-parse", "--short", "HEAD"], check=True,
                              capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run([*git, "status", "--porcelain", "src"], check=True,
                           capture_output=True, text=True).stdout.strip()
    after = f"this tree, HEAD {head_rev}{' + uncommitted src' if dirty else ''}"
    head = [(f"## {datetime.date.today()}: Octave table ({version}; --before {args.before}, "
             f"after = {after})"),
            (f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load "
             f"{load}; {args.samples} samples of the noise run (seed 2), {args.rounds} rounds "
             f"alternating A B / B A in one Octave process; cpu µs per sample, medians; ratio: "
             f"median of per-round before / after")]
    print("\n".join(head), flush=True)
    lines = head + _octave_table(args)
    lines.append(f"# load at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(lines[-1])
    out = args.out
    kept = out.read_text() if out.exists() else ""
    out.write_text(kept + "\n" + "\n".join(lines) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer samples and repeats")
    parser.add_argument("--octave", action="store_true",
                        help="only the Octave table: --before's MATLAB export against this tree's")
    parser.add_argument("--before", default="5812754", metavar="REV",
                        help="git revision of the Octave table's before variant")
    parser.add_argument("--rounds", type=int, default=3, help="Octave table rounds")
    parser.add_argument("--samples", type=int, default=1000, help="Octave table samples")
    parser.add_argument("--families", nargs="+", metavar="NAME",
                        help="Octave table: these families only (default: OCTAVE_CASES)")
    parser.add_argument("--out", type=Path, default=HERE / "last_run_export.txt",
                        help="Octave table: the file its section is appended to")
    parser.add_argument("--write-matlab-child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.write_matlab_child:
        models, out, prefix = args.write_matlab_child
        _write_matlab_child(Path(models), Path(out), prefix)
        return
    if args.octave:
        _octave_main(args)
        return
    repeats, n_loop, n_python = (3, N_LOOP // 10, 500) if args.quick else (7, N_LOOP, 2000)
    fit_rec, use_rec = simulate_experiment("sine", 1), simulate_experiment("decay", 2)
    lines = [(f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load "
              f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}; C: cc -O2 -std=c99, "
              f"{n_loop} samples x {repeats} interleaved repeats (median); Octave: "
              f"{n_python} samples; Python: bench_stream.python_latency, {n_python} samples")]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        data = tmp / "sensor.txt"
        np.savetxt(data, use_rec.sensor, fmt="%.17g")
        comps, builds = {}, {}
        for name, size in FAMILIES:
            label = f"{name} {size}"
            comps[label] = fit_compensator(fit_rec, size, model=name, diagnose=False)
            for double in (False, True):
                builds[label, double] = _build(comps[label], tmp / f"{name}-{size}-{double}",
                                               double)
        ns = {key: [] for key in builds}
        state = {}
        for _ in range(repeats):
            for key, build in builds.items():
                state[key], t = _time(build["timer"], data, n_loop)
                ns[key].append(t)
        header = (f"{'model':<12} {'state B f/d':>12} {'step B':>7} {'.text B':>8} "
                  f"{'C ns f/d':>13} {'octave µs':>10} {'step µs':>8} {'proc/64 µs':>10} "
                  f"{'py loop µs':>10}")
        lines.append(header)
        print("\n".join(lines), flush=True)
        for label, comp in comps.items():
            f32 = builds[label, False]
            octave = _octave_us(comp, tmp / f"m-{label.replace(' ', '-')}", data, n_python)
            py = python_latency(comp, use_rec.sensor[:n_python], repeats=max(3, repeats // 2))
            row = (f"{label:<12} {state[label, False]:>5} / {state[label, True]:<5} "
                   f"{f32['step']:>7} {f32['text']:>8} "
                   f"{statistics.median(ns[label, False]):>6.0f} / "
                   f"{statistics.median(ns[label, True]):<5.0f} "
                   f"{'-' if octave is None else f'{octave:.0f}':>10} {py['step_us']:>8.1f} "
                   f"{py['process_chunk_us']:>10.2f} {py['python_loop_us']:>10.1f}")
            lines.append(row)
            print(row, flush=True)
    lines.append(f"# load at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(lines[-1])
    # this table replaces the file's first one; the Octave sections (--octave) appended
    # after it stay
    out = HERE / "last_run_export.txt"
    old = out.read_text() if out.exists() else ""
    octave_sections = old[old.index("\n## "):] if "\n## " in old else ""
    out.write_text("\n".join(lines) + "\n" + octave_sections)


if __name__ == "__main__":
    main()
