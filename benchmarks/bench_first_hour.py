"""A new user's first hour, timed: a clean venv, the README's first command, then its own-data
walk-through up to the first fitted model (issue 27), for git revisions side by side.

Run:  python benchmarks/bench_first_hour.py [--rev REV ...] [--rounds N] [--out FILE]
      (about 5 minutes per revision and round on 2 cores; default revisions bad4e5b, the commit
      before issue 27's work, and HEAD)

For each revision, in a temporary folder:

1. ``git archive REV`` unpacked as the user's copy of the project; ``python -m venv`` (no
   system site packages) whose ``bin`` is first on PATH for every later step;
2. the README's first command, read literally from that revision's README.md (the first
   command of its first fenced block, e.g. ``pip install . && hystkit demo``), run in the
   project's folder, each ``&&`` part timed on its own (pip uses this machine's configured
   index and wheel folder, as a user's would: downloads are not part of the time);
3. the README's section "Your own files" (its walk-through block, found by the parser of
   ``tests/docs/test_readme_walkthrough.py``) in an empty folder: the commands before its first
   ``hystkit fit`` (the stand-in CSV), then that fit three times: as the user meets it after
   the demo (numba's default cache, which the demo filled), *cold* (``NUMBA_CACHE_DIR`` a fresh
   empty folder: every kernel the fit needs compiled) and *warm* (the same folder again); the
   outputs of a run are removed before the next; then the rest of the block.

Rounds are paired and interleaved (A B, then B A), so bursts of the machine's load hit all
revisions alike; reported are per-round values, medians and the median of the per-round
ratios. "to the first model" adds up venv, the first command, the stand-in file and the fit
after the demo: a new user's wait from a clean machine to a model file of their own CSV.
A README without a fenced first command, without the section, or whose walk-through has no
``hystkit fit`` stops the run with one line naming what is missing.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BEFORE = "bad4e5b"  # the last commit before issue 27's work (2026-11-28 14:13)
WALKTHROUGH_TEST = REPO / "tests" / "docs" / "test_readme_walkthrough.py"
_FIRST_FENCE = re.compile(r"^```[^\n]*\n(.*?)^```", re.MULTILINE | re.DOTALL)
_HEREDOC = re.compile(r"<<-?\s*(['\"]?)(\w+)\1")
STEP_TIMEOUT_S = 3600


class ReadmeError(RuntimeError):
    """The README lacks what the benchmark follows (one line naming it)."""


@dataclass
class Run:
    """One revision, one round: seconds and exit code per step, in order."""

    seconds: dict[str, float] = field(default_factory=dict)
    exits: dict[str, int] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def first_command(readme: Path) -> list[str]:
    """The README's first set-up command, split at its ``&&`` into the parts timed one by
    one (each part as shell text; comments dropped)."""
    text = readme.read_text(encoding="utf-8")
    block = _FIRST_FENCE.search(text)
    if block is None:
        raise ReadmeError(f"{readme.name}: no fenced code block, so no first command to follow")
    line = next((ln for ln in block.group(1).splitlines()
                 if ln.strip() and not ln.lstrip().startswith("#")), None)
    if line is None:
        raise ReadmeError(f"{readme.name}: the first fenced block holds no command")
    parts, current = [], []
    for token in shlex.split(line, comments=True):
        if token == "&&":
            parts.append(shlex.join(current))
            current = []
        else:
            current.append(token)
    parts.append(shlex.join(current))
    return parts


def walkthrough(readme: Path) -> str:
    """The bash block of the README's section "Your own files", by the test suite's parser."""
    spec = importlib.util.spec_from_file_location("_readme_walkthrough", WALKTHROUGH_TEST)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.README = readme  # its parser reads the module's README: this revision's
    code = module.walkthrough()
    if code is None:
        raise ReadmeError(f"{readme.name}: no section whose title starts with 'Your own files' "
                          f"holding the bash walk-through (compensate ... .mat) that "
                          f"{WALKTHROUGH_TEST.relative_to(REPO)} runs")
    return code


def commands(script: str) -> list[str]:
    """`script` as its commands: a line with its backslash continuations and its here-
    documents; comment and blank lines between commands dropped."""
    lines, out, k = script.splitlines(), [], 0
    while k < len(lines):
        line = lines[k]
        k += 1
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        command = [line]
        while command[-1].endswith("\\") and k < len(lines):
            command.append(lines[k])
            k += 1
        for match in _HEREDOC.finditer("\n".join(command)):
            while k < len(lines):
                command.append(lines[k])
                k += 1
                if command[-1].strip() == match.group(2):
                    break
        out.append("\n".join(command))
    return out


def split_at_fit(script: str, readme: Path) -> tuple[str, str, str]:
    """``(before, fit, after)``: the walk-through around its first ``hystkit fit``."""
    parts = commands(script)
    at = next((i for i, c in enumerate(parts) if c.startswith("hystkit fit")), None)
    if at is None:
        raise ReadmeError(f"{readme.name}: the walk-through 'Your own files' has no 'hystkit fit' "
                          f"command, so no first fitted model to time")
    return "\n".join(parts[:at]), parts[at], "\n".join(parts[at + 1:])


def _environment(venv: Path, cache: Path | None) -> dict[str, str]:
    """A user's shell with the venv activated: its bin first, nothing of this process's
    Python setup; numba's cache in `cache` (None: numba's default, beside the package)."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "PYTHONDONTWRITEBYTECODE",
                        "PYTHONPYCACHEPREFIX", "NUMBA_CACHE_DIR", "VIRTUAL_ENV")}
    env.update(PATH=f"{venv / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}",
               VIRTUAL_ENV=str(venv), MPLBACKEND="Agg")
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = str(cache)
    return env


def _step(run: Run, label: str, script: str, cwd: Path, env: dict[str, str],
          ok: tuple[int, ...] = (0,)) -> bool:
    """Run `script` with bash, time it under `label`; False (and a note) on another exit."""
    t0 = time.perf_counter()
    done = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=STEP_TIMEOUT_S, check=False)
    run.seconds[label] = time.perf_counter() - t0
    run.exits[label] = done.returncode
    if done.returncode not in ok:
        tail = (done.stderr.strip() or done.stdout.strip()).splitlines()[-3:]
        run.notes.append(f"{label}: exit {done.returncode}: {' | '.join(tail)}")
        return False
    return True


def _new_files(folder: Path, before: set[Path]) -> None:
    """Remove what appeared in `folder` since `before` (a fit's outputs, before its rerun)."""
    for path in set(folder.iterdir()) - before:
        shutil.rmtree(path) if path.is_dir() else path.unlink()


def first_hour(rev: str, tmp: Path) -> Run:
    """Every step for revision `rev` in the empty folder `tmp` (see the module)."""
    run = Run()
    project, venv, own = tmp / "project", tmp / "venv", tmp / "own"
    project.mkdir()
    own.mkdir()
    archive = subprocess.run(["git", "-C", str(REPO), "archive", rev], capture_output=True,
                             check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(project)], input=archive, check=True)
    readme = project / "README.md"
    setup = first_command(readme)
    before_fit, fit, after_fit = split_at_fit(walkthrough(readme), readme)

    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    run.seconds["python -m venv"] = time.perf_counter() - t0
    env = _environment(venv, None)
    for part in setup:
        if not _step(run, part, part, project, env):
            return run
    if not _step(run, "walk-through before its fit", before_fit, own, env):
        return run
    present = set(own.iterdir())
    # exit 3: the fit ran and wrote its model, which failed its guards (said in the table)
    if not _step(run, "fit, after the demo", fit, own, env, ok=(0, 3)):
        return run
    for state in ("cold", "warm"):
        _new_files(own, present)
        _step(run, f"fit, {state}", fit, own, _environment(venv, tmp / "numba-cache"),
              ok=(0, 3))
    if after_fit.strip():
        _step(run, "rest of the walk-through", after_fit, own,
              _environment(venv, tmp / "numba-cache"))
    first = ["python -m venv", *setup, "walk-through before its fit", "fit, after the demo"]
    run.seconds["to the first model"] = sum(run.seconds[label] for label in first)
    return run


def _readme(rev: str, folder: Path) -> Path:
    """Revision `rev`'s README.md, written into `folder`."""
    readme = folder / "README.md"
    readme.write_bytes(subprocess.run(["git", "-C", str(REPO), "show", f"{rev}:README.md"],
                                      capture_output=True, check=True).stdout)
    return readme


def _resolve(rev: str) -> tuple[str, str]:
    """``(short hash, subject)`` of `rev`."""
    shown = subprocess.run(["git", "-C", str(REPO), "log", "-1", "--format=%h %s", rev],
                           capture_output=True, text=True, check=True).stdout.strip()
    short, _, subject = shown.partition(" ")
    return short, subject


def _machine() -> str:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"platform {platform.platform()}; cpus {os.cpu_count()}; load average {load} at "
            f"start; python {platform.python_version()} ({sys.executable} -m venv)")


def table(revs: list[tuple[str, str]], runs: dict[str, list[Run]]) -> list[str]:
    """Per step: each revision's rounds and median [s], and the median per-round ratio of
    the last revision to the first; exit codes where a step did not exit 0."""
    labels: list[str] = []
    for rev_runs in runs.values():
        for run in rev_runs:
            labels += [label for label in run.seconds if label not in labels]
    labels.sort(key=lambda label: label == "to the first model")  # the sum last
    first, last = revs[0][0], revs[-1][0]
    head = f"{'step':<34}" + "".join(f"{rev + ' [s]':>24}" for rev, _ in revs)
    lines = [head + (f"{last + '/' + first:>16}" if len(revs) > 1 else "")]
    for label in labels:
        cells = []
        for rev, _ in revs:
            values = [r.seconds.get(label) for r in runs[rev]]
            shown = " ".join("-" if v is None else f"{v:.1f}" for v in values)
            known = [v for v in values if v is not None]
            median = f"{statistics.median(known):.1f}" if known else "-"
            exits = {r.exits.get(label) for r in runs[rev]} - {None, 0}
            flag = f" exit {','.join(map(str, sorted(exits)))}" if exits else ""
            cells.append(f"{median + flag + ' (' + shown + ')':>24}")
        pairs = [(a.seconds.get(label), b.seconds.get(label))
                 for a, b in zip(runs[first], runs[last], strict=True)]
        ratios = [b / a for a, b in pairs if a and b is not None]
        ratio = f"{statistics.median(ratios):.2f}x" if ratios and len(revs) > 1 else ""
        lines.append(f"{label[:33]:<34}" + "".join(cells) + f"{ratio:>16}")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rev", action="append", default=None, metavar="REV",
                        help=f"a git revision to follow (repeat for several; default "
                             f"{BEFORE} and HEAD)")
    parser.add_argument("--rounds", type=int, default=2, help="rounds per revision (2)")
    parser.add_argument("--out", type=Path, default=None,
                        help="also write the report here (benchmarks/last_run_first_hour.txt)")
    args = parser.parse_args()
    revs = [_resolve(rev) for rev in (args.rev or [BEFORE, "HEAD"])]
    followed = {}
    for rev, _ in revs:  # a README the benchmark cannot follow stops it before any install
        with tempfile.TemporaryDirectory() as folder:
            readme = _readme(rev, Path(folder))
            try:
                followed[rev] = (" && ".join(first_command(readme)),
                                 split_at_fit(walkthrough(readme), readme)[1])
            except ReadmeError as exc:
                sys.exit(f"bench_first_hour: revision {rev}: {exc}")
    title = (f"A new user's first hour: clean venv, README's first command, its walk-through "
             f"'Your own files' to the first fitted model; wall time [s], median (rounds), "
             f"{args.rounds} interleaved rounds")
    lines = [title, _machine()]
    lines += [f"revision {rev}: {subject}" for rev, subject in revs]
    t_total = time.perf_counter()
    runs: dict[str, list[Run]] = {rev: [] for rev, _ in revs}
    for k in range(args.rounds):
        for rev, _ in (revs if k % 2 == 0 else revs[::-1]):  # A B, then B A
            with tempfile.TemporaryDirectory(prefix=f"first-hour-{rev}-") as folder:
                print(f"round {k + 1}, {rev} ...", flush=True)
                runs[rev].append(first_hour(rev, Path(folder)))
    lines += ["", *table(revs, runs), ""]
    for rev, _ in revs:
        setup, fit = followed[rev]
        lines.append(f"{rev}: first command `{setup}`; first fit `{' '.join(fit.split())}`")
        lines += [f"  note, round {k + 1}: {note}" for k, run in enumerate(runs[rev])
                  for note in run.notes]
    lines.append(f"total {time.perf_counter() - t_total:.0f} s")
    report = "\n".join(lines)
    print(report)
    if args.out is not None:
        args.out.write_text(report + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
