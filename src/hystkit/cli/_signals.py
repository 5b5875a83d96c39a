"""SIGTERM as an exception in the CLI's main thread; quiet worker processes.

Ctrl-C already raises KeyboardInterrupt; SIGTERM by default kills the process on the spot,
which would skip the atomic writers' cleanup. While a command runs, SIGTERM raises
`~hystkit.errors.Terminated` instead, so ``finally`` blocks remove temporaries and `main`
prints one line and exits 143. Forked worker processes (``select --jobs``) get the default
actions back, so on Ctrl-C (sent to the whole process group) they end without a traceback and
the parent reports once.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from ..errors import Terminated

_active = False  # a command is running in this process (workers forked now need the reset)


def _raise_terminated(signum: int, frame: object) -> None:
    raise Terminated


def _quiet_child() -> None:
    if _active:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, signal.SIG_DFL)


os.register_at_fork(after_in_child=_quiet_child)


@contextmanager
def signals_as_exceptions() -> Iterator[None]:
    """Within the block, SIGTERM raises `Terminated` (main thread only; restored after)."""
    global _active
    if threading.current_thread() is not threading.main_thread():
        yield  # signal handlers can only be set from the main thread
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    was_active, _active = _active, True
    try:
        yield
    finally:
        _active = was_active
        signal.signal(signal.SIGTERM, previous)
