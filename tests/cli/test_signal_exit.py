"""How a command stopped by a signal ends its workers and itself, without ``os._exit``.

A worker forked after the signal (a pool still starting) dies by that signal's default action;
before the stopped program exits, `end_workers` terminates and joins every worker (killing one
that ignores SIGTERM), so multiprocessing's exit handler has none left to wait for. Each case
runs in a fresh interpreter: the signal handlers and forks are process-wide.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and fork")


def _python(code: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=False)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["sigint", "sigterm"])
def test_a_worker_forked_after_the_signal_dies_by_it(sig: signal.Signals) -> None:
    code = ("import multiprocessing, os, signal, sys\n"
            "from hystkit.cli._signals import signals_as_exceptions\n"
            "from hystkit.errors import Terminated\n"
            "def work():\n"
            "    print('the worker ran', flush=True)\n"
            "with signals_as_exceptions():\n"
            "    try:\n"
            f"        os.kill(os.getpid(), {int(sig)})\n"
            "    except (KeyboardInterrupt, Terminated):\n"
            "        pass\n"
            "    worker = multiprocessing.get_context('fork').Process(target=work)\n"
            "    worker.start()\n"
            "    worker.join()\n"
            "print(worker.exitcode)\n")
    done = _python(code)
    assert done.returncode == 0, done.stderr
    # killed by the signal (a shell would say 128 + n), before running anything of its own
    assert done.stdout.splitlines() == [str(-sig)]
    assert done.stderr == ""


def test_end_workers_terminates_and_joins_every_worker() -> None:
    code = ("import multiprocessing, signal, time\n"
            "from hystkit.cli._signals import end_workers\n"
            "def busy(ready):\n"
            "    ready.set()\n"
            "    time.sleep(600)\n"
            "def deaf(ready):\n"
            "    signal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
            "    ready.set()\n"
            "    time.sleep(600)\n"
            "fork = multiprocessing.get_context('fork')\n"
            "workers = []\n"
            "for target in (busy, deaf):\n"
            "    ready = fork.Event()\n"
            "    workers.append(fork.Process(target=target, args=(ready,)))\n"
            "    workers[-1].start()\n"
            "    assert ready.wait(60)\n"
            "end_workers(timeout=0.5)\n"
            "print(multiprocessing.active_children(), [w.exitcode for w in workers])\n")
    done = _python(code)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["[]", f"[{-signal.SIGTERM},", f"{-signal.SIGKILL}]"]


def test_end_workers_without_multiprocessing_does_nothing() -> None:
    done = _python("import sys\n"
                   "from hystkit.cli._signals import end_workers\n"
                   "end_workers()\n"
                   "print('multiprocessing' in sys.modules)\n")
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False"]


# The program (`hystkit.cli.program`) around a stand-in command that leaves what a signal can
# leave: an object whose finaliser fails at the interpreter's exit and a line still buffered
# for a stdout pipe that has no reader. With SIGNAL set, a signal stops the command; with AGAIN,
# Ctrl-C comes again during the exit.
_PROGRAM = """\
import atexit, os, signal, sys
import hystkit.cli._main as _main
from hystkit.cli._signals import signals_as_exceptions
from hystkit.errors import Terminated

class HalfBuilt:
    def __del__(self):
        raise AttributeError("a finaliser of something the signal cut short")

def command(argv):
    try:
        with signals_as_exceptions():
            atexit.register([HalfBuilt()].clear)  # released at the interpreter's exit
            print("a line still in the buffer")
            if "AGAIN" in os.environ:  # a second Ctrl-C while the interpreter exits
                atexit.register(lambda: (os.kill(os.getpid(), signal.SIGINT),
                                         print("the exit went on", file=sys.stderr)))
            if "SIGNAL" in os.environ:
                os.kill(os.getpid(), int(os.environ["SIGNAL"]))
            return 0
    except KeyboardInterrupt:
        return _main._stopped(signal.SIGINT)
    except Terminated:
        return _main._stopped(signal.SIGTERM)

_main._main = command
_main.program()
"""


def _program_into_a_closed_pipe(**env: str) -> tuple[int, str]:
    """Exit code and stderr of `_PROGRAM`, its stdout a pipe whose reader has left."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        done = subprocess.run([sys.executable, "-c", _PROGRAM], stdout=write_end,
                              stderr=subprocess.PIPE, text=True, timeout=120, check=False,
                              env={k: v for k, v in {**os.environ, **env}.items()
                                   if k not in ("PYTHONUNBUFFERED", "HYSTKIT_DEBUG")})
    finally:
        os.close(write_end)
    return done.returncode, done.stderr


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["sigint", "sigterm"])
def test_a_stopped_program_exits_with_its_code_and_one_line(sig: signal.Signals) -> None:
    code, err = _program_into_a_closed_pipe(SIGNAL=str(int(sig)))
    assert code == 128 + sig
    assert err.splitlines() == [{signal.SIGINT: "hystkit: interrupted",
                                 signal.SIGTERM: "hystkit: terminated (SIGTERM)"}[sig]]


def test_without_a_signal_a_failing_finaliser_is_shown_and_a_gone_reader_is_exit_1() -> None:
    code, err = _program_into_a_closed_pipe()
    assert code == 1  # the interpreter's own flush would have made it 120
    assert "BrokenPipeError" not in err
    assert "a finaliser of something the signal cut short" in err  # only a signal hides it


def test_a_second_ctrl_c_during_the_exit_ends_the_process_by_sigint() -> None:
    code, err = _program_into_a_closed_pipe(SIGNAL=str(int(signal.SIGINT)), AGAIN="1")
    assert code == -signal.SIGINT  # at once, by the signal: a shell reports 130
    assert err.splitlines() == ["hystkit: interrupted"]
