"""``hystkit warm``: compile the numba kernels of the common commands ahead, once per
installation (issue 29), with a line per step and an estimate of the rest.

Without it the first ``fit``, ``compare`` or ``control`` compiles what it needs itself (and
says so on stderr): 10-60 s on 2 cores. ``warm`` runs those commands once, in a temporary
folder, on short recordings of the virtual sensor: for each family ``fit`` (with its band),
``evaluate``, ``stream --in`` (its compiled per-sample kernel) and ``compare``, then ``control --experiment sine`` in both schemes; their output
is dropped. What gets compiled, with which argument types, is therefore what the commands use
today, not a list kept beside them. numba keeps the kernels in its on-disk cache, where every
later process loads them (see numba's ``NUMBA_CACHE_DIR``). Run again, it only loads them.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from numba import config

from .. import _compilation
from .._compilation import compiler_seconds, listen
from ..control import _kernel
from ..io import Recording, write_recording
from ..models import FAMILIES
from ..parallel._contract import make_numba_ready
from ..sensors import simulate_experiment
from ._common import UsageError
from ._main import main

__all__ = ["run_steps", "run_warm", "warm_steps"]

# Seconds of each step on the 2-core machine (2026-11-28, load ~1.5): its work with the
# kernels cached, and what compiling them adds with an empty cache (34 s in all). The estimate
# printed as it goes is the work left plus the compilation left, rescaled by the time the
# steps so far spent in numba's compiler against these (loading cached kernels takes a small
# share of it, a slower or busier machine more).
STEP_SECONDS = {"recordings": (0.7, 0.7), "mpl": (0.3, 4.6), "bobbio": (0.1, 1.9),
                "boucwen": (0.9, 0.4), "chua": (0.7, 1.8), "gpreisach": (0.8, 2.8),
                "ladder": (1.0, 0.6), "mpl-g": (0.3, 1.0), "mpl-poly": (0.5, 2.0),
                "pi": (0.2, 1.0), "pl": (0.6, 0.9), "preisach": (0.6, 0.1),
                "control": (1.0, 0.7)}
DEFAULT_SECONDS = (0.8, 2.0)  # a family registered later
SOLVER_SECONDS = 8.0  # compiling the shared least-squares solver: the first family's fit
N_SAMPLES = 2000  # of each recording: 50 s at 40 Hz, enough for every family's default size


@dataclass(frozen=True)
class WarmStep:
    """One step: its name, its run (which returns a note or None), and its seconds on the
    2-core machine: its work once compiled, and what compiling adds."""

    name: str
    run: Callable[[], str | None]
    work_seconds: float
    compile_seconds: float


def warm_steps(folder: Path, models: Sequence[str], control: bool) -> list[WarmStep]:
    """The recordings, each family of `models` (mPL first), then ``control`` if asked."""
    names = sorted(models, key=lambda name: (name != "mpl", name))
    steps = [WarmStep("recordings", lambda: _write_recordings(folder),
                      *STEP_SECONDS["recordings"])]
    for i, name in enumerate(names):
        work, compiling = STEP_SECONDS.get(name, DEFAULT_SECONDS)
        steps.append(WarmStep(name, _family_step(folder, name), work,
                              compiling + (SOLVER_SECONDS if i == 0 else 0.0)))
    if control:
        steps.append(WarmStep("control", _control_step(folder), *STEP_SECONDS["control"]))
    return steps


def run_steps(steps: Sequence[WarmStep], progress: Callable[[str], None]) -> float:
    """Run `steps`, one line each to `progress` (seconds, note, estimate of the rest); the
    wall seconds of all."""
    listen()
    make_numba_ready()  # numba's one-off start (~0.2 s), not a kernel: outside the estimate
    t_start, compiling_start, expected = time.perf_counter(), compiler_seconds(), 0.0
    for i, step in enumerate(steps, 1):
        t_step = time.perf_counter()
        note = step.run()
        expected += step.compile_seconds
        rate = (compiler_seconds() - compiling_start) / max(expected, 1e-9)
        left = sum(s.work_seconds + rate * s.compile_seconds for s in steps[i:])
        tail = f" (about {left:.0f} s left)" if i < len(steps) else ""
        progress(f"[{i}/{len(steps)}] {step.name}: {time.perf_counter() - t_step:.1f} s"
                 f"{f' ({note})' if note else ''}{tail}")
    return time.perf_counter() - t_start


def _write_recordings(folder: Path) -> None:
    """The fitting and validation recordings (noise seed 1, sine seed 2), cut short."""
    for name, excitation, seed in (("fit.csv", "noise", 1), ("val.csv", "sine", 2)):
        rec = simulate_experiment(excitation, seed)
        short = Recording(rec.time[:N_SAMPLES], rec.sensor[:N_SAMPLES],
                          rec.position[:N_SAMPLES], source=rec.source, units=rec.units)
        write_recording(short, folder / name)


def _command(*argv: str, ran: Sequence[int] = (0, 3)) -> str | None:
    """Run ``hystkit ARGV`` here with its output dropped; None, or why it failed. An exit code
    in `ran` counts as run (a fit that fails its guards, exit 3, has compiled all the same)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    if code in ran:
        return None
    lines = err.getvalue().strip().splitlines()
    return f"{argv[0]} exited {code}: {lines[-1] if lines else 'no message'}"


def _family_step(folder: Path, name: str) -> Callable[[], str | None]:
    def run() -> str | None:
        fit, val, model = str(folder / "fit.csv"), str(folder / "val.csv"), folder / f"{name}.json"
        notes = [_command("fit", fit, "--model", name, "--out", str(model))]
        if model.exists():
            notes.append(_command("evaluate", str(model), val))
            # a model that failed its guards is refused by stream (exit 2): nothing to compile
            notes.append(_command("stream", str(model), "--in", val, ran=(0, 2)))
        notes.append(_command("compare", fit, val, "--models", name,
                              "--out", str(folder / f"compare-{name}")))
        return "; ".join(note for note in notes if note) or None

    return run


def _control_step(folder: Path) -> Callable[[], str | None]:
    def run() -> str | None:
        notes = [_command("control", "--scheme", scheme, "--experiment", "sine",
                          "--out", str(folder / f"control-{scheme}"))
                 for scheme in ("direct", "weighting")]
        return "; ".join(note for note in notes if note) or None

    return run


def _kernel_cache() -> str:
    """Where numba caches hystkit's kernels: ``NUMBA_CACHE_DIR`` if set, else one kernel's
    folder (``__pycache__`` beside the sources, or numba's user-wide cache where that is not
    writable)."""
    if config.CACHE_DIR:
        return config.CACHE_DIR
    return f"e.g. {_kernel.identity_step.stats.cache_path}"


def _models(text: str | None) -> list[str]:
    if text is None:
        return list(FAMILIES)
    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names or any(name not in FAMILIES for name in names):
        raise UsageError(f"--models {text}: choose among {', '.join(sorted(FAMILIES))}")
    return names


def run_warm(args: argparse.Namespace) -> int:
    """``hystkit warm``: the common commands run once, their kernels compiled and cached."""
    _compilation.announce(None)  # the progress lines say it
    models, control = _models(args.models), not args.no_control
    commands = ("fit, evaluate, stream, compare and control" if control
                else "fit, evaluate, stream and compare")
    with tempfile.TemporaryDirectory(prefix="hystkit-warm-") as folder:
        steps = warm_steps(Path(folder), models, control)
        estimate = sum(s.work_seconds + s.compile_seconds for s in steps)
        print(f"hystkit warm: compiling the numba kernels of {commands} into numba's cache "
              f"({_kernel_cache()}): about {estimate:.0f} s on 2 cores the first time, a few "
              f"seconds once compiled", flush=True)
        seconds = run_steps(steps, lambda line: print(f"  {line}", flush=True))
    print(f"done in {seconds:.1f} s: later runs load these kernels from the cache")
    return 0
