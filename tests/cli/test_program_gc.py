"""The ``hystkit`` program tunes its own garbage collector; a caller of ``main([...])`` keeps its.

Run as the program (``argv`` None), `hystkit.cli.main` raises the full-collection threshold and
freezes the heap before the interpreter shuts down (a shorter `fit`: benchmarks/README.md,
start-up). A test, notebook or script calling ``main([...])`` in its own process must not find
its collector changed. Checked in fresh interpreters, since this test session's collector is
its own business.
"""

from __future__ import annotations

import subprocess
import sys

from hystkit.cli._main import _PROGRAM_GC_THRESHOLDS

_REPORT = "import gc; print(gc.get_threshold(), gc.get_freeze_count() > 0)"


def _gc_after(call: str) -> str:
    code = ("import contextlib, gc, io, sys\n"
            "from hystkit.cli import main\n"
            "sys.argv = ['hystkit', 'datasets', 'list']\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    code = {call}\n"
            "assert code == 0, code\n"
            f"{_REPORT}")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True, timeout=120).stdout.strip()


def test_the_program_raises_the_full_collection_threshold_and_freezes_at_the_end():
    assert _gc_after("main()") == f"{_PROGRAM_GC_THRESHOLDS} True"


def test_an_in_process_call_leaves_the_callers_collector_alone():
    default = subprocess.run([sys.executable, "-c", _REPORT], capture_output=True, text=True,
                             check=True, timeout=60).stdout.strip()
    assert default.endswith("False")  # a fresh interpreter: nothing frozen
    assert _gc_after("main(['datasets', 'list'])") == default
