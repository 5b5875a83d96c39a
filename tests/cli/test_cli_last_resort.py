"""What `main` does with what escapes a command: one line and a documented exit code each."""

from __future__ import annotations

import signal

import pytest

from hystkit.cli import cmd_core, main
from hystkit.errors import InputError, Terminated


def _raising(exc: BaseException):
    def run(args):
        raise exc
    return run


@pytest.mark.parametrize(("exc", "code", "line"), [
    (ValueError("boom\nsecond line"), 70,
     ("hystkit: internal error: ValueError: boom second line (please report; HYSTKIT_DEBUG=1 "
     "shows the traceback)")),
    (InputError("x.csv: column 'a'\nrow 3: bad"), 2,
     "hystkit: error: x.csv: column 'a' row 3: bad"),
    (KeyboardInterrupt(), 130, "hystkit: interrupted"),
    (Terminated(), 143, "hystkit: terminated (SIGTERM)"),
    (MemoryError(), 2, ("hystkit: error: out of memory (try a smaller input, model size or "
                       "--chunk-size)")),
])
def test_each_escape_is_one_line_with_its_exit_code(exc, code, line, monkeypatch, capsys):
    monkeypatch.delenv("HYSTKIT_DEBUG", raising=False)
    monkeypatch.setattr(cmd_core, "_evaluate", _raising(exc))
    assert main(["evaluate", "m.json", "d.csv"]) == code
    err = capsys.readouterr().err
    assert err.splitlines() == [line]


def test_debug_variable_shows_the_traceback_of_an_internal_error(monkeypatch, capsys):
    monkeypatch.setenv("HYSTKIT_DEBUG", "1")
    monkeypatch.setattr(cmd_core, "_evaluate", _raising(TypeError("bug")))
    assert main(["evaluate", "m.json", "d.csv"]) == 70
    err = capsys.readouterr().err
    assert "Traceback" in err and "TypeError: bug" in err
    assert err.splitlines()[-1].startswith("hystkit: internal error: TypeError: bug")


def test_signal_handlers_are_restored_after_a_command(monkeypatch, capsys):
    seen = {}

    def run(args):
        seen["term"] = signal.getsignal(signal.SIGTERM)
        return 0

    before = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    monkeypatch.setattr(cmd_core, "_evaluate", run)
    assert main(["evaluate", "m.json", "d.csv"]) == 0
    assert seen["term"] not in (signal.SIG_DFL, before[0])  # raised Terminated meanwhile
    assert (signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)) == before
