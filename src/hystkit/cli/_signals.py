"""Ctrl-C and SIGTERM as exceptions in the CLI's main thread; worker processes end quietly.

Ctrl-C already raises KeyboardInterrupt; SIGTERM by default kills the process on the spot,
which would skip the atomic writers' cleanup. While a command runs, SIGTERM raises
`~hystkit.errors.Terminated` instead, so ``finally`` blocks remove temporaries and `main`
prints one line and exits 143. Both handlers first terminate this process's multiprocessing
workers (the processes of a local Dask cluster, `hystkit.parallel`), so a cluster being shut
down does not wait for their work. Forked workers get the default actions back: on Ctrl-C (the
terminal signals the whole process group) or when terminated they end without a traceback, and
the parent reports once; a worker a pool forks after the signal (one still starting) ends at
once, by that signal's default action. Before the stopped program exits, `end_workers` joins
every worker, so multiprocessing's exit handlers have none left to wait for, and
`quiet_exit` keeps the interpreter's exit from reporting what the signal cut short.
"""

from __future__ import annotations

import concurrent.futures.thread  # noqa: F401  (registers its at-fork hooks before ours)
import logging  # also registers its at-fork hooks before ours
import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from ..errors import Terminated

_active = False  # a command is running in this process (workers forked now need the reset)
_received: int | None = None  # the last signal the running command got
_owner = os.getpid()  # the process running the command (not a forked worker)
_forking = False  # between this process's at-fork hooks
_PR_SET_PDEATHSIG = 1  # prctl(2) option
_previous_excepthook = threading.excepthook


def received_signal() -> int | None:
    """The signal (SIGINT or SIGTERM) the current or last command received, if any.

    An exception that follows a signal (a library's cleanup failing half-way, e.g. a process
    pool interrupted while starting) is the signal's consequence, not a bug of its own.
    """
    return _received


def _terminate_workers() -> list:
    """SIGTERM to this process's live multiprocessing children; returns them."""
    multiprocessing = sys.modules.get("multiprocessing")
    if multiprocessing is None:  # never imported: no workers
        return []
    children = multiprocessing.active_children()
    for child in children:
        child.terminate()
    return children


def _stop_workers() -> None:
    # What the stopped workers' connections log from a cluster's event loop (closed streams,
    # futures whose exception nobody reads) is the signal's consequence: not shown.
    logging.disable(logging.CRITICAL)
    _terminate_workers()


def end_workers(timeout: float = 5.0) -> None:
    """Terminate and join this process's multiprocessing children, the workers of a command
    stopped by a signal: the interpreter's exit (multiprocessing's handler joins every live
    child) then has nothing to wait for. One still alive after `timeout` seconds is killed."""
    for child in _terminate_workers():
        child.join(timeout)
        if child.is_alive():
            child.kill()
            child.join()


def quiet_exit() -> None:
    """The exit of a program a signal stopped says nothing more: finalisers that fail then are
    not shown, as they belong to objects the signal left half-built (a multiprocessing
    ``Finalize`` interrupted before its key, an LLVM handle of a compilation cut short;
    ``HYSTKIT_DEBUG=1`` shows them), and a second Ctrl-C meanwhile ends the process at once by
    SIGINT's default action (a shell's 130 still), not with a KeyboardInterrupt's traceback."""
    if os.environ.get("HYSTKIT_DEBUG", "") in ("", "0"):
        sys.unraisablehook = _ignore_unraisable
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not an ignored one
        signal.signal(signal.SIGINT, signal.SIG_DFL)


def _ignore_unraisable(unraisable: object) -> None:
    """Refers to no global: it may run while the interpreter clears this module."""


def _die_by(signum: int) -> None:
    """End this forked worker by `signum`'s default action: no handler, no Python cleanup
    (what it copied from its parent is not its to flush); its parent sees it killed by the
    signal, a shell reports 128 + `signum`."""
    signal.signal(signum, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signum})
    os.kill(os.getpid(), signum)  # delivered before kill returns (unblocked, to itself)


def _stopping(signum: int) -> bool:
    """Common part of the handlers: note the signal, stop the workers; False: do not raise
    now (a forked worker that is about to reset its handlers, or a fork in progress)."""
    global _received
    if os.getpid() != _owner:  # a worker forked a moment ago, before `_quiet_child` ran
        _die_by(signum)
        return False
    _received = signum
    if _forking:
        # An exception raised inside another module's at-fork hook (logging's) would only be
        # printed and ignored: raise it from a timer once the fork has returned.
        signal.setitimer(signal.ITIMER_REAL, 0.005)
        return False
    _stop_workers()
    return True


def _raise_for(signum: int) -> None:
    raise KeyboardInterrupt if signum == signal.SIGINT else Terminated


def _on_signal(signum: int, frame: object) -> None:
    if _stopping(signum):
        _raise_for(signum)


def _on_alarm(signum: int, frame: object) -> None:
    """The deferred exception of a signal that arrived while forking."""
    if _received is None or os.getpid() != _owner:
        return
    if _forking:
        signal.setitimer(signal.ITIMER_REAL, 0.005)
        return
    _stop_workers()
    _raise_for(_received)


def _fork_starts() -> None:
    global _forking
    _forking = True


def _fork_done() -> None:
    global _forking
    _forking = False


def _quiet_thread_errors(args: threading.ExceptHookArgs) -> None:
    """After a signal, errors in helper threads (a process pool's manager finding its workers
    gone) are the signal's consequence: no traceback for them."""
    if _received is None:
        _previous_excepthook(args)


def _die_with_parent() -> None:
    """Linux: have the kernel send SIGTERM when the parent ends, so a worker forked while the
    parent was being stopped (too late for its terminate) cannot outlive it."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    except (OSError, AttributeError):  # not Linux: the parent's terminate has to do
        return
    if os.getppid() != _owner:  # the parent ended before the request took effect
        _die_by(signal.SIGTERM)


def _quiet_child() -> None:
    global _forking
    _forking = False
    if _active:
        if _received is not None:  # forked by a pool still starting after the signal
            _die_by(_received)
        if sys.platform.startswith("linux"):
            _die_with_parent()
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        if signal.getsignal(signal.SIGINT) is _on_signal:
            signal.signal(signal.SIGINT, signal.SIG_DFL)


# Registered after logging's hooks (imported above for this), so that ours enclose them:
# `before` hooks run in reverse order of registration, `after_*` hooks in order.
os.register_at_fork(before=_fork_starts, after_in_parent=_fork_done,
                    after_in_child=_quiet_child)


@contextmanager
def signals_as_exceptions() -> Iterator[None]:
    """Within the block, SIGTERM raises `Terminated` and SIGINT KeyboardInterrupt, each after
    stopping worker processes (main thread only; the previous handlers are restored)."""
    global _active, _received, _owner, _previous_excepthook
    _received, _owner = None, os.getpid()
    if threading.current_thread() is not threading.main_thread():
        yield  # signal handlers can only be set from the main thread
        return
    previous_term = signal.signal(signal.SIGTERM, _on_signal)
    previous_alarm = signal.signal(signal.SIGALRM, _on_alarm)
    previous_int = signal.getsignal(signal.SIGINT)
    if previous_int is signal.default_int_handler:  # leave an ignored SIGINT (nohup) ignored
        signal.signal(signal.SIGINT, _on_signal)
    _previous_excepthook, threading.excepthook = threading.excepthook, _quiet_thread_errors
    was_active, _active = _active, True
    logging_level = logging.root.manager.disable
    try:
        yield
    finally:
        logging.disable(logging_level)
        _active = was_active
        threading.excepthook = _previous_excepthook
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGTERM, previous_term)
        signal.signal(signal.SIGALRM, previous_alarm)
        if previous_int is signal.default_int_handler:
            signal.signal(signal.SIGINT, previous_int)
