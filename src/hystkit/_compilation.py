"""What numba's compiler costs a process, and one line for the user when a run has to compile.

numba reports every entry into its compiler (a compilation, or a load from its on-disk cache,
both under its global compiler lock) as a ``numba:compiler_lock`` event and every actual
compilation as a ``numba:compile`` event. `listen` registers one listener for each, once per
process; it is called by what times or runs kernels (`hystkit.identification.FitTimer`), so
this module loads numba only there and a command's start stays free of it.

* `compiler_seconds`: the time this thread has spent in numba's compiler, which a fit's
  ``seconds`` leaves out (issue 29: a 0.05 s fit was stored as 17-21 s).
* `announce`: the ``hystkit`` program's request for one line on stderr at the first
  compilation (a first run after installing: the kernels are compiled once, then loaded from
  the cache). A worker forked from the program shares the flag that the line was written
  (one byte of shared memory), so a parallel run writes it once too.
"""

from __future__ import annotations

import mmap
import sys
import threading
import time

__all__ = ["announce", "compiler_seconds", "listen"]

# The line to write at the first compilation (None: none), and whether it was written, in
# memory that forked workers share.
_notice: str | None = None
_written: mmap.mmap | None = None
_listening = False
_time_in_compiler = threading.local()


def announce(message: str | None) -> None:
    """Write `message` to stderr at the first numba compilation of this process or of a
    worker forked from it after this call (None: write nothing)."""
    global _notice, _written
    _notice = message
    if _written is None:
        _written = mmap.mmap(-1, 1)


def compiler_seconds() -> float:
    """Wall seconds this thread has spent in numba's compiler since `listen` was first called
    (compiling kernels, loading them from the cache, waiting for another thread's compiler)."""
    return getattr(_time_in_compiler, "seconds", 0.0)


def listen() -> None:
    """Register the listeners on numba's compiler events (once per process)."""
    global _listening
    if _listening:
        return
    from numba.core import event

    class InCompiler(event.Listener):
        """Adds up each thread's time in the compiler, outermost entries only (the lock is
        re-entrant: compiling a kernel enters it again for each kernel it calls)."""

        def on_start(self, event: event.Event) -> None:
            local = _time_in_compiler
            depth = getattr(local, "depth", 0)
            if depth == 0:
                local.entered = time.perf_counter()
            local.depth = depth + 1

        def on_end(self, event: event.Event) -> None:
            local = _time_in_compiler
            depth = getattr(local, "depth", 0)
            if depth == 0:  # entered before the listener was registered
                return
            local.depth = depth - 1
            if depth == 1:
                local.seconds = compiler_seconds() + time.perf_counter() - local.entered

    class FirstCompilation(event.Listener):
        def on_start(self, event: event.Event) -> None:
            _write_notice()

        def on_end(self, event: event.Event) -> None:
            pass

    event.register("numba:compiler_lock", InCompiler())
    event.register("numba:compile", FirstCompilation())
    _listening = True


def _write_notice() -> None:
    if _notice is None or _written is None or _written[0]:
        return
    _written[0] = 1
    print(_notice, file=sys.stderr, flush=True)
