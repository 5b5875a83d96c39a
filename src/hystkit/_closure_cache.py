"""numba's on-disk cache for a kernel built as a closure over other compiled functions.

The control loop and the compiled stream are built per combination of a family's block steps:
each step is a closure constant, so numba inlines it (as an argument each call would cost a
function call and the reference counting of its arrays: measured 12 % slower on the mPL
loop). numba keys a closure's cache entries by its bytecode and its pickled closure variables;
the steps are dispatchers, which pickle with a random id of their process, so with plain
``cache=True`` no other process would find an entry (the control loop compiled on every run:
0.6-1.5 s of each ``hystkit control``). `compile_closure` keys the entry by the steps' stable
names instead (`stable_name`: module, qualified name, the file's modification time and size).
"""

from __future__ import annotations

import hashlib
import os
import sys
from collections.abc import Callable, Sequence

from numba import njit
from numba.core.caching import FunctionCache

__all__ = ["compile_closure", "stable_name"]


def compile_closure(func: Callable, steps: Sequence) -> Callable:
    """``njit(func)`` for `func`, a closure over the compiled `steps`, cached on disk under
    the steps' names when every step has a stable one (else compiled in this process only).

    numba names a compiled function by its qualified name and a number counted per process;
    closures over two combinations compiled in two processes can get the same number, and
    their symbols (the function, its environment) then clash in a process that loads both
    from the cache: the combination in the qualified name keeps them apart.
    """
    names = [stable_name(step) for step in steps]
    if not all(names):
        return njit(func)
    combination = hashlib.sha256("|".join(names).encode()).hexdigest()[:16]
    func.__qualname__ = f"{func.__qualname__}_{combination}"
    compiled = njit(func)
    compiled._cache = _ClosureCache(func, combination)
    return compiled


def stable_name(step) -> str | None:
    """The name that means `step`'s code in every process: module, qualified name and the
    module file's modification time and size (so that a cached loop does not outlive an edit
    of the step); None for a step that is not a module-level function of a file."""
    func = step.py_func
    module = sys.modules.get(func.__module__)
    path = getattr(module, "__file__", None)
    if path is None or getattr(module, func.__qualname__, None) is not step:
        return None
    stat = os.stat(path)
    return f"{func.__module__}:{func.__qualname__}:{stat.st_mtime_ns}:{stat.st_size}"


class _ClosureCache(FunctionCache):
    """numba's on-disk cache of one closure kernel, keyed by its steps' names.

    numba keys a closure's entries by its bytecode and its pickled closure variables; the
    steps are dispatchers, which pickle with a random id of their process, so with plain
    ``cache=True`` no other process would find an entry (the loop compiled on every run:
    0.6-1.5 s of each ``hystkit control``). The key here is numba's with the hash of the
    steps' names (`stable_name`) in place of the pickle; the loop's qualified name, which
    names the cache files, carries it too.
    """

    def __init__(self, py_func, combination: str) -> None:
        super().__init__(py_func)
        self._combination = combination

    def _index_key(self, sig, codegen):
        code_hash = hashlib.sha256(self._py_func.__code__.co_code).hexdigest()
        return sig, codegen.magic_tuple(), (code_hash, self._combination)
