"""Marks given to the whole suite by rule (issue 28.5), so that no test file has to carry them.

``slow``: a test that starts a process (an interpreter, the C compiler, GNU Octave, Chromium,
Sphinx, a Dask cluster), in its own code, a fixture it uses or a helper of ``tests/`` it calls.
``python -m pytest -m "not slow"`` is the quick local loop; CI runs everything.

Under ``pytest -n N`` (pytest-xdist) the tests are spread a file at a time (``--dist loadfile``
in pyproject.toml), so that a file's module fixtures (the site build, the demo run, a set of
fits) are made once. ``--dist loadgroup`` with per-file groups for just those files would
spread the rest finer, but pytest-xdist 3.8 does not group under pytest 9 (it renames
``item._nodeid``, which pytest 9 no longer reads): every test of a group ran apart.
"""

from __future__ import annotations

import inspect
import os
import types
from functools import cache
from pathlib import Path

import pytest
from threadpoolctl import threadpool_limits

TESTS = Path(__file__).resolve().parent

# What a test calls to start a process: the subprocess module (the interpreter, cc, octave,
# chromium, sphinx), hostile's helper around it, and the Dask cluster's worker processes.
PROCESS_STARTERS = frozenset({"subprocess", "run_subprocess", "Popen", "LocalCluster"})


def _under_tests(code: types.CodeType) -> bool:
    return Path(code.co_filename).resolve().is_relative_to(TESTS)


def _in_tests(module: types.ModuleType) -> bool:
    path = getattr(module, "__file__", None)
    return path is not None and Path(path).resolve().is_relative_to(TESTS)


def _codes(code: types.CodeType):
    """`code` and the code of the functions, lambdas and comprehensions defined inside it."""
    yield code
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield from _codes(const)


@cache
def _starts_process(func: types.FunctionType) -> bool:
    """Whether `func`, or a function of ``tests/`` it names (recursively), names a process
    starter. Only names are read: a test that calls a helper which may start a process counts."""
    seen: set[types.CodeType] = set()
    todo = [func]
    while todo:
        fn = inspect.unwrap(todo.pop())
        fn = getattr(getattr(fn, "hypothesis", None), "inner_test", fn)
        code = getattr(fn, "__code__", None)
        if code is None or code in seen or not _under_tests(code):
            continue
        seen.add(code)
        names = {n for c in _codes(code) for n in c.co_names}
        if names & PROCESS_STARTERS:
            return True
        scope = getattr(fn, "__globals__", {})
        for name in names:
            obj = scope.get(name)
            if isinstance(obj, types.ModuleType) and _in_tests(obj):  # helper.function(...)
                todo += [vars(obj)[n] for n in names if inspect.isfunction(vars(obj).get(n))]
            elif inspect.isfunction(obj):
                todo.append(obj)
    return False


def _fixture_defs(item: pytest.Item):
    """The definitions of every fixture `item` uses (directly or through other fixtures)."""
    info = getattr(item, "_fixtureinfo", None)
    if info is not None:
        for defs in info.name2fixturedefs.values():
            yield from defs


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        funcs = [getattr(item, "function", None), *(d.func for d in _fixture_defs(item))]
        if any(f is not None and _starts_process(f) for f in funcs):
            item.add_marker(pytest.mark.slow)
    # Files that start processes first (the site build, Octave, cc): under -n they would
    # otherwise start last and run alone at the end (--no-loadscope-reorder keeps this order).
    slow_files = {i.path for i in items if i.get_closest_marker("slow")}
    items.sort(key=lambda i: i.path not in slow_files)  # stable: the files keep their order


def pytest_configure(config: pytest.Config) -> None:
    # Under pytest-xdist each worker keeps one BLAS thread, as scikit-learn's conftest does:
    # with OpenBLAS's default of one thread per core, two workers on two cores run four
    # threads that spin against each other (a 191 x 191 SVD took 35-41 ms of CPU instead of
    # 8-18 ms, a QR of 8200 x 192 164-179 ms instead of 40-43 ms, on this 2-core machine
    # under load). The `hystkit` program sets one BLAS thread itself (cli/_main.py).
    if os.environ.get("PYTEST_XDIST_WORKER"):
        threadpool_limits(limits=1, user_api="blas")  # kept for the worker's whole run
