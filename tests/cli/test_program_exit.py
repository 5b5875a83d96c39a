"""The ``hystkit`` program ends its process without the interpreter's teardown, losing nothing.

`hystkit.cli.program` (the console script, ``python -m hystkit``) runs the command, then the
exit handlers, flushes the standard streams and ends the process: the teardown that would
release every module's objects one by one is skipped (a shorter ``fit``: benchmarks/README.md,
start-up). Checked in fresh interpreters: what a normal exit guarantees still happens, the
teardown does not, and a running non-daemon thread gets the normal exit, which waits for it
(the thread's last line comes before the exit handler's).
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
    later = ("def late():\n"
             "    time.sleep(0.5)\n"
             "    print('thread finished', flush=True)\n"
             "threading.Thread(target=late).start()\n")
    done = _program(["datasets", "list"], before=later)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines.index("thread finished") == lines.index("exit handler ran") - 1
