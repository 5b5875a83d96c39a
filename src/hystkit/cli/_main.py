"""``hystkit`` command line: each subcommand parses, calls the library, writes, returns a code.

Subcommands are the rows of `hystkit.cli._commands.COMMANDS` (name, help, options function,
run function); only the chosen command's modules are imported.

Exit codes: 0 success; 2 an error the user can fix (one ``hystkit: error:`` line); 3 work ran
but failed its guards (`GUARD_EXIT`); 70 an internal error (a bug: one line, the traceback with
``HYSTKIT_DEBUG=1``); 130 interrupted (Ctrl-C); 143 terminated (SIGTERM). Interrupted or
failed commands leave no partial output: every writer publishes atomically.
"""

from __future__ import annotations

import errno
import gc
import os
import signal
import sys
import traceback
from collections.abc import Sequence
from typing import NoReturn

from .. import __version__
from .._compilation import announce
from ..errors import HystkitError, Terminated
from . import _commands
from ._common import INTERNAL_EXIT, Parser
from ._signals import end_workers, quiet_exit, received_signal, signals_as_exceptions

__all__ = ["main", "program"]

# The program's garbage collector, the one start-up setting kept (issue 28: measured 2026-11-28,
# benchmarks/bench_startup.py): full collections only after 100 (not 10) young ones, and the
# heap frozen before the interpreter's shutdown. Loading numba and its cached kernels builds
# ~500 000 long-lived objects that Python's default walks again every 25 % of growth and at
# shutdown; the two together cut 22 % of a 1-cell `fit`'s and 33 % of an `evaluate`'s wall time.
_PROGRAM_GC_THRESHOLDS = (700, 10, 100)
# Thread counts OpenBLAS reads when it loads (numpy's and scipy's copies each start their pool
# then); the CLI process sets the first to 1 unless one of them is set. Every BLAS call of
# hystkit's that matters already runs on one thread (fits, their workers: tall, narrow
# problems where more threads lose), so the pools only cost start-up: ~0.04 s of CPU per
# library, plus its threads' spinning on a busy machine (benchmarks/README.md, start-up).
_BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")
# The program's line at its first numba compilation (`hystkit._compilation.announce`): the first
# run after installing compiles the kernels it needs (2026-11-28, 2 cores, load 3, a fresh
# numba cache: `fit --model mpl` 5.5 s wall / 3.2 s user, `compare` of every family 30 s wall /
# 24 s user, against about 1 and 6 s with the kernels in numba's cache).
COMPILING_NOTICE = ("hystkit: compiling numba kernels, once per installation: this run takes "
                    "a few seconds (fit) to half a minute (compare) longer, later runs load "
                    "them from numba's cache ('hystkit warm' compiles them ahead)")


def _parser(command: str | None = None, *, options: bool = True) -> Parser:
    """The ``hystkit`` parser: every subcommand of the table (`hystkit.cli._commands`) by name
    and help; given `command`, the options of that one only, else (`options`) of all.

    A command line naming its subcommand imports that command's options function only (a
    shorter start); ``--help``, ``--version`` and an unknown name need no options at all
    (``options=False``: the error of an unknown name still lists every subcommand).
    """
    parser = Parser(prog="hystkit", description="Hysteresis compensation for lousy "
                    "(3D-printed, soft) sensors.")
    parser.add_argument("--version", action="version", version=f"hystkit {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    chosen = command if _commands.command(command) is not None else None
    for row in _commands.COMMANDS:
        p = sub.add_parser(row.name, help=row.help)
        if row.name == chosen or (chosen is None and options):
            _add_options(row, p)
    return parser


def _add_options(row: _commands.Command, p: Parser) -> None:
    """Add `row`'s options (and ``--force`` unless it has one) and its run function to `p`."""
    _commands.resolve(row.options)(p)
    if row.run is not None:
        p.set_defaults(run=row.run)
    if not any("--force" in a.option_strings for a in p._actions):
        p.add_argument("--force", action="store_true", help="overwrite existing output files")


def _named_command(argv: Sequence[str]) -> str | None:
    """The subcommand a command line names: its first word, unless that is an option."""
    return argv[0] if argv and not argv[0].startswith("-") else None


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split("\n"))


def _stopped(signum: int) -> int:
    """One line for a command stopped by a signal; exit 128 + its number (130, 143)."""
    if signum == signal.SIGTERM:
        print("hystkit: terminated (SIGTERM)", file=sys.stderr)
    else:
        print("hystkit: interrupted", file=sys.stderr)
    return 128 + signum


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code (see the module docstring).

    Run as the program (`argv` None) it tunes the process's garbage collector for a short
    life (`_PROGRAM_GC_THRESHOLDS`, and a frozen heap at the end, which the interpreter's
    shutdown does not walk again), has OpenBLAS start one thread unless the environment says
    otherwise (`_BLAS_THREAD_VARIABLES`), and a run that has to compile numba kernels says
    so on stderr (`COMPILING_NOTICE`); stopped by a signal, it terminates and joins the
    workers the command forked (`hystkit.cli._signals.end_workers`) before returning 130 or
    143, so that the interpreter's exit has none to wait for, and that exit says nothing more
    (`hystkit.cli._signals.quiet_exit`); and it flushes stdout itself, so that a reader that
    left is exit 1 (or the signal's code), not a traceback.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments after the program name (``["fit", "data.csv", ...]``); None reads
        ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit code: 0 success, 1 stdout closed by its reader, 2 an error the user can fix
        (one ``hystkit: error:`` line on stderr, bad arguments included), 3 guards failed
        (`GUARD_EXIT`), 70 an internal error, 130 interrupted, 143 terminated. ``--help`` and
        ``--version`` print and raise ``SystemExit(0)``, as argparse does.
    """
    if argv is None:
        gc.set_threshold(*_PROGRAM_GC_THRESHOLDS)
        if not any(os.environ.get(name) for name in _BLAS_THREAD_VARIABLES):
            os.environ["OPENBLAS_NUM_THREADS"] = "1"  # before numpy is imported
        announce(COMPILING_NOTICE)
    code = _main(argv)
    if argv is None and received_signal() is not None:
        end_workers()  # the interpreter's exit would join them
        quiet_exit()
    if argv is None:
        code = _flush_streams(code)
        gc.freeze()  # the shutdown's collections skip the frozen heap
    return code


def _flush_streams(code: int) -> int:
    """Flush stdout and stderr before the interpreter's exit does: its flush into a pipe whose
    reader left (output still buffered) prints 'Exception ignored' and exits 120. Such a
    stream is pointed at devnull, its unread output dropped; a stdout gone makes the exit 1
    unless the code already says something. Either may be closed (``>&-``: None); any other
    error (a full disk) is left for the interpreter's flush to report."""
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except BrokenPipeError:  # the reader left (`hystkit ... | head`): not our error
            os.dup2(os.open(os.devnull, os.O_WRONLY), stream.fileno())
            if stream is sys.stdout:
                code = code or 1
        except OSError:
            pass
    return code


def program() -> NoReturn:
    """The ``hystkit`` program (its console script and ``python -m hystkit``): `main` on
    ``sys.argv``, then the end of the process with its exit code.
    """
    sys.exit(main())


def _main(argv: Sequence[str] | None) -> int:
    try:
        with signals_as_exceptions():
            named = _named_command(sys.argv[1:] if argv is None else argv)
            args = _parser(named, options=False).parse_args(argv)
            run = _commands.resolve(args.run) if isinstance(args.run, str) else args.run
            return run(args)
    except HystkitError as exc:
        if received_signal() is not None:  # e.g. a reader child killed by the same Ctrl-C
            return _stopped(received_signal())
        print(f"hystkit: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return _stopped(signal.SIGINT)
    except Terminated:
        return _stopped(signal.SIGTERM)
    except BrokenPipeError:
        # The reader went away (`hystkit ... | head`): not our error. Point stdout at devnull so
        # the interpreter's final flush does not raise again (Python docs, signal module).
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except MemoryError:
        print("hystkit: error: out of memory (try a smaller input, model size or "
              "--chunk-size)", file=sys.stderr)
        return 2
    except Exception as exc:  # noqa: BLE001  (the last resort is the point)
        if received_signal() is not None:  # cleanup that failed because of the signal
            return _stopped(received_signal())
        if isinstance(exc, OSError) and exc.errno == errno.ENAMETOOLONG:
            # A path no check caught (the writers check theirs before any work): the user's.
            print(f"hystkit: error: {exc.filename}: file name too long", file=sys.stderr)
            return 2
        # Last resort. Anything here is a bug (user errors are HystkitErrors): say so on one
        # line rather than with a traceback; the hostile tests treat this exit code as failure.
        if os.environ.get("HYSTKIT_DEBUG", "") not in ("", "0"):
            traceback.print_exc()
        print(f"hystkit: internal error: {type(exc).__name__}: {_one_line(exc)} (please "
              f"report; HYSTKIT_DEBUG=1 shows the traceback)", file=sys.stderr)
        return INTERNAL_EXIT


if __name__ == "__main__":
    program()
