"""The ``hystkit`` program tunes its own process; a caller of ``main([...])`` keeps its settings.

Run as the program (``argv`` None), `hystkit.cli.main` raises the full-collection threshold,
freezes the heap before the interpreter shuts down, and has OpenBLAS start one thread unless the
environment names a thread count (a shorter `fit`: benchmarks/README.md, start-up). A test,
notebook or script calling ``main([...])`` in its own process must find its collector and its
environment unchanged. Checked in fresh interpreters, since this test session is its own business.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from hystkit.cli._main import _BLAS_THREAD_VARIABLES, _PROGRAM_GC_THRESHOLDS

_REPORT = "import gc; print(gc.get_threshold(), gc.get_freeze_count() > 0)"


def _gc_after(call: str) -> str:
    return _run(call, _REPORT)


def _run(call: str, report: str, env: dict[str, str] | None = None) -> str:
    code = ("import contextlib, gc, io, sys\n"
            "from hystkit.cli import main\n"
            "sys.argv = ['hystkit', 'datasets', 'list']\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    code = {call}\n"
            "assert code == 0, code\n"
            f"{report}")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True, timeout=120, env=env).stdout.strip()


def _env(**values: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in _BLAS_THREAD_VARIABLES}
    return {**env, **values}


# After the command: the variable, and the thread count numpy's OpenBLAS took.
_BLAS_REPORT = ("import os, numpy, threadpoolctl\n"
                "threads = {i['num_threads'] for i in threadpoolctl.threadpool_info()\n"
                "           if i['internal_api'] == 'openblas'}\n"
                "print(os.environ.get('OPENBLAS_NUM_THREADS'), sorted(threads))")


def test_the_program_raises_the_full_collection_threshold_and_freezes_at_the_end():
    assert _gc_after("main()") == f"{_PROGRAM_GC_THRESHOLDS} True"


def test_an_in_process_call_leaves_the_callers_collector_alone():
    default = subprocess.run([sys.executable, "-c", _REPORT], capture_output=True, text=True,
                             check=True, timeout=60).stdout.strip()
    assert default.endswith("False")  # a fresh interpreter: nothing frozen
    assert _gc_after("main(['datasets', 'list'])") == default


def test_the_program_starts_openblas_with_one_thread():
    assert _run("main()", _BLAS_REPORT, _env()) == "1 [1]"


@pytest.mark.parametrize("name", _BLAS_THREAD_VARIABLES)
def test_a_thread_count_in_the_environment_is_left_as_set(name):
    out = _run("main()", _BLAS_REPORT, _env(**{name: "2"}))
    assert out == ("2 [2]" if name == "OPENBLAS_NUM_THREADS" else "None [2]")


def test_an_in_process_call_leaves_the_environment_alone():
    assert _run("main(['datasets', 'list'])", "import os\nprint(os.environ.get("
                "'OPENBLAS_NUM_THREADS'))", _env()) == "None"
