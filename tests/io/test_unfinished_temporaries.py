"""A signal that lands between creating a temporary and the ``try`` that discards it (Ctrl-C
is raised between any two bytecodes) leaves no file once the interpreter exits
(``hystkit.io._unfinished``)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from hystkit.io import _atomic, _unfinished
from hystkit.io._output_checks import TEMP_MARK


def _interrupted_after_creating(monkeypatch: pytest.MonkeyPatch) -> None:
    create = _atomic._create_temporary

    def create_then_interrupt(path: Path) -> Path:
        create(path)
        raise KeyboardInterrupt  # the signal, before `_staged` holds the temporary

    monkeypatch.setattr(_atomic, "_create_temporary", create_then_interrupt)


def test_a_temporary_cut_off_by_a_signal_is_removed(tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    _interrupted_after_creating(monkeypatch)
    with pytest.raises(KeyboardInterrupt), _atomic.atomic_output(tmp_path / "out.csv"):
        pass
    left = [p.name for p in tmp_path.iterdir()]
    assert len(left) == 1 and TEMP_MARK in left[0]  # what the signal left, before exit
    _unfinished.remove_unfinished()
    assert list(tmp_path.iterdir()) == []


def test_finished_outputs_are_forgotten(tmp_path: Path) -> None:
    before = dict(_unfinished._unfinished)
    with _atomic.atomic_output(tmp_path / "a.csv") as tmp:
        tmp.write_text("1\n")
    with pytest.raises(RuntimeError), _atomic.atomic_output(tmp_path / "b.csv"):
        raise RuntimeError
    assert _unfinished._unfinished == before
    assert [p.name for p in tmp_path.iterdir()] == ["a.csv"]


def test_another_process_temporaries_are_left(tmp_path: Path) -> None:
    path = tmp_path / f".x{TEMP_MARK}0000"
    path.write_text("")
    _unfinished._unfinished[path] = -1  # registered by the parent of a forked worker
    try:
        _unfinished.remove_unfinished()
        assert path.exists()
    finally:
        _unfinished.forget(path)


def test_the_interpreter_exit_removes_them(tmp_path: Path) -> None:
    code = textwrap.dedent(f"""
        from pathlib import Path
        from hystkit.io import _atomic
        create = _atomic._create_temporary
        def create_then_interrupt(path):
            create(path)
            raise KeyboardInterrupt
        _atomic._create_temporary = create_then_interrupt
        try:
            with _atomic.atomic_output(Path({str(tmp_path)!r}) / "out.csv"):
                pass
        except KeyboardInterrupt:
            print(len(list(Path({str(tmp_path)!r}).iterdir())))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True)
    assert done.stdout.strip() == "1"  # left when the signal landed ...
    assert list(tmp_path.iterdir()) == []  # ... and gone after the exit
