"""Every code block of README.md and docs/**/*.md is checked by the test suite (issue 11.4).

- ``python`` blocks run in order, per file, in one shared namespace, in a temporary working
  folder (files they write stay there).
- ``bash`` blocks: every ``hystkit ...`` command is parsed by hystkit's own parser (option
  names, choices and values, so a renamed option fails here). In ``docs/`` the commands are then
  run in order, in the same temporary folder as the file's python blocks. README.md's command
  tour is parsed only: it uses files the reader brings (``a.csv``, ``train.csv``) and runs every
  model (minutes); the README walk-through test runs its own-data path.
- A block preceded by ``<!-- skip-test: reason -->`` is not run (its commands are still parsed);
  ``test_skipped_blocks_say_why`` lists them with their reasons.
- Other blocks are left alone: output and settings (``text``, unlabelled, ``toml``), and C or
  MATLAB listings (the export tests compile and run the generated code itself).
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import pytest

from hystkit.errors import InputError

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[2]
FILES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
_FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.MULTILINE | re.DOTALL)
_SKIP = re.compile(r"<!--\s*skip-test:\s*(.*?)\s*-->\s*$", re.DOTALL)


@dataclass(frozen=True)
class Block:
    path: Path
    line: int
    language: str
    code: str
    skip: str  # the reason of a skip-test marker, "" when the block runs

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def blocks_of(path: Path) -> list[Block]:
    text = path.read_text(encoding="utf-8")
    found = []
    for match in _FENCE.finditer(text):
        before = text[:match.start()].rstrip("\n").rsplit("\n", 1)[-1]
        marker = _SKIP.search(before)
        found.append(Block(path, text.count("\n", 0, match.start()) + 1, match.group(1),
                           match.group(2), marker.group(1) if marker else ""))
    return found


def commands_of(code: str) -> list[list[str]]:
    """The ``hystkit`` command lines of a bash block as argument lists (continuations joined,
    comments dropped, the shell's redirections and what follows a pipe left out)."""
    return [words for words, _ in expected_commands(code)]


def expected_commands(code: str) -> list[tuple[list[str], int]]:
    """:func:`commands_of` with each command's expected exit code: 0, or N for a line ending
    in the comment ``# exit N`` (a fit written for inspection exits 3)."""
    joined = re.sub(r"\\\n", " ", code)
    commands = []
    for line in joined.splitlines():
        expected = re.search(r"#\s*exit (\d+)\s*$", line)
        # Quotes kept while cutting, so a quoted ';' (--sep ';') is an argument, not an operator.
        lexer = shlex.shlex(line, posix=False, punctuation_chars="|<>&;")
        lexer.whitespace_split, lexer.commenters = True, "#"
        tokens = list(lexer)
        cut = next((i for i, t in enumerate(tokens) if set(t) <= set("|<>&;")), len(tokens))
        words = shlex.split(" ".join(tokens[:cut]))
        if words and words[0] == "hystkit":
            commands.append((words[1:], int(expected.group(1)) if expected else 0))
    return commands


ALL = {path: blocks_of(path) for path in FILES}


def test_every_page_is_found_and_blocks_parse():
    assert ROOT / "docs" / "control.md" in ALL
    assert sum(len(b) for b in ALL.values()) > 0


@pytest.mark.parametrize("block", [b for blocks in ALL.values() for b in blocks
                                   if b.language == "bash" and commands_of(b.code)],
                         ids=lambda b: b.where)
def test_bash_commands_parse(block):
    from hystkit.cli._main import _parser

    for argv in commands_of(block.code):
        _parser().parse_args(argv)  # UsageError (one line) on a wrong option or value


def _runs_commands(block: Block) -> bool:
    return block.language == "bash" and block.path.parent != ROOT and bool(
        commands_of(block.code))


RUNNABLE = {path: [b for b in blocks if not b.skip and (b.language == "python"
                                                          or _runs_commands(b))]
            for path, blocks in ALL.items()}


@pytest.mark.parametrize("path", [p for p, blocks in RUNNABLE.items() if blocks],
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_page_examples_run(path, tmp_path, monkeypatch):
    from hystkit.cli._main import main

    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    for block in RUNNABLE[path]:
        if block.language == "python":
            try:
                exec(compile(block.code, block.where, "exec"), namespace)  # noqa: S102 (docs)
            except InputError as exc:
                _skip_without_shared_data(block, str(exc))
                raise
            continue
        for argv, expected in expected_commands(block.code):
            out = io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
                code = main(argv)
            if code != expected:
                _skip_without_shared_data(block, out.getvalue())
            assert code == expected, f"{block.where}: hystkit {' '.join(argv)} -> {code}:\n" \
                                     f"{out.getvalue()[-2000:]}"


def _skip_without_shared_data(block, message: str) -> None:
    """Pages on the public data sets (docs/real_data.md) need ../shared/data, which a clone
    elsewhere does not have: skip them then, as tests/datasets does; any other error fails."""
    if "shared data not found" in message:
        pytest.skip(f"{block.where}: the public data sets are absent ({message.strip()[:120]})")


def test_skipped_blocks_say_why():
    skipped = [b for blocks in ALL.values() for b in blocks if b.skip]
    for block in skipped:
        assert len(block.skip) > 10, f"{block.where}: give the reason of the skip"
