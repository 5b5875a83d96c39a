"""The ``hystkit`` program ends with the interpreter's normal exit, its heap frozen, losing nothing.

`hystkit.cli.program` (the console script, ``python -m hystkit``) runs the command, flushes
the standard streams, freezes the heap (``gc.freeze``: the shutdown's collections do not walk
the objects numba built again, `hystkit.cli._main`) and exits with the command's code through
``sys.exit``. Checked in fresh interpreters: what a normal exit guarantees happens (exit
handlers, the whole output), the frozen objects' finalisers do not run at teardown, and a
running non-daemon thread is waited for (its last line comes before the exit handler's).
"""

from __future__ import annotations

import subprocess
import sys

# An object whose finaliser only the interpreter's teardown runs, and an exit handler.
_SETUP = ("import atexit, sys, threading, time\n"
          "class Witness:\n"
          "    def __del__(self):\n"
          "        print('teardown ran', flush=True)\n"
          "witness = Witness()\n"
          "atexit.register(print, 'exit handler ran')\n")


def _program(argv: list[str], before: str = "") -> subprocess.CompletedProcess[str]:
    code = (f"{_SETUP}{before}\n"
            "from hystkit.cli import program\n"
            f"sys.argv = ['hystkit', *{argv!r}]\n"
            "program()\n")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=False)


def test_the_program_runs_exit_handlers_flushes_and_skips_the_teardown():
    done = _program(["datasets", "list"])
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "piezo_micromanipulator" in done.stdout  # the command's whole output arrived
    assert lines[-1] == "exit handler ran"
    assert "teardown ran" not in done.stdout


def test_the_normal_exit_runs_the_teardown_the_program_skips():
    # The witness above works: a plain exit does run its finaliser.
    done = subprocess.run([sys.executable, "-c", _SETUP + "sys.exit(0)"], capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.stdout.splitlines() == ["exit handler ran", "teardown ran"]


def test_the_exit_code_of_a_failed_command_is_kept():
    done = _program(["evaluate", "missing-model.json", "missing.csv"])
    assert done.returncode == 2
    assert done.stderr.startswith("hystkit: error: ")
    assert "teardown ran" not in done.stdout


def test_a_running_non_daemon_thread_gets_the_normal_exit_which_waits_for_it():
    # The thread starts its last stretch only when the command has returned, so it is still
    # running when the program decides how to end, however slow the machine (a fixed sleep
    # raced the command under load).
    later = ("import hystkit.cli._main as _main\n"
             "returned = threading.Event()\n"
             "def command(*args, _main_=_main.main):\n"
             "    try:\n"
             "        return _main_(*args)\n"
             "    finally:\n"
             "        returned.set()\n"
             "_main.main = command\n"
             "def late():\n"
             "    returned.wait()\n"
             "    time.sleep(0.3)\n"
             "    print('thread finished', flush=True)\n"
             "threading.Thread(target=late).start()\n")
    done = _program(["datasets", "list"], before=later)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "piezo_micromanipulator" in done.stdout
    # the normal exit waited for the thread (ending the process at once would have ended it
    # mid-sleep), then ran the exit handlers
    assert lines[-2:] == ["thread finished", "exit handler ran"]
