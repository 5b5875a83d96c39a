"""Ctrl-C and SIGTERM as exceptions in the CLI's main thread; worker processes end quietly.

Ctrl-C already raises KeyboardInterrupt; SIGTERM by default kills the process on the spot,
which would skip the atomic writers' cleanup. While a command runs, SIGTERM raises
`~hystkit.errors.Terminated` instead, so ``finally`` blocks remove temporaries and `main`
prints one line and exits 143. Both handlers first terminate this process's multiprocessing
workers (``select --jobs``), so a pool being shut down does not wait for their work. Forked
workers get the default actions back: on Ctrl-C (the terminal signals the whole process
group) or when terminated they end without a traceback, and the parent reports once.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from ..errors import Terminated

_active = False  # a command is running in this process (workers forked now need the reset)


def _stop_workers() -> None:
    multiprocessing = sys.modules.get("multiprocessing")
    if multiprocessing is None:  # never imported: no workers
        return
    for child in multiprocessing.active_children():
        child.terminate()


def _on_sigint(signum: int, frame: object) -> None:
    _stop_workers()
    raise KeyboardInterrupt


def _on_sigterm(signum: int, frame: object) -> None:
    _stop_workers()
    raise Terminated


def _quiet_child() -> None:
    if _active:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        if signal.getsignal(signal.SIGINT) is _on_sigint:
            signal.signal(signal.SIGINT, signal.SIG_DFL)


os.register_at_fork(after_in_child=_quiet_child)


@contextmanager
def signals_as_exceptions() -> Iterator[None]:
    """Within the block, SIGTERM raises `Terminated` and SIGINT KeyboardInterrupt, each after
    stopping worker processes (main thread only; the previous handlers are restored)."""
    global _active
    if threading.current_thread() is not threading.main_thread():
        yield  # signal handlers can only be set from the main thread
        return
    previous_term = signal.signal(signal.SIGTERM, _on_sigterm)
    previous_int = signal.getsignal(signal.SIGINT)
    if previous_int is signal.default_int_handler:  # leave an ignored SIGINT (nohup) ignored
        signal.signal(signal.SIGINT, _on_sigint)
    was_active, _active = _active, True
    try:
        yield
    finally:
        _active = was_active
        signal.signal(signal.SIGTERM, previous_term)
        if previous_int is signal.default_int_handler:
            signal.signal(signal.SIGINT, previous_int)
