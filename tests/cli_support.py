"""What the command-line tests share: one call of ``hystkit`` in this process."""

from __future__ import annotations

import pytest

from hystkit.cli import main


def run_cli(capsys: pytest.CaptureFixture[str], *argv: object) -> tuple[int, str, str]:
    """``main`` on the stringified arguments: ``(exit code, stdout, stderr)`` of this call
    only (whatever was printed before, e.g. by fixtures, is dropped first)."""
    capsys.readouterr()
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err
