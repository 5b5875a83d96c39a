"""A command line that names its subcommand builds the parser only up to the module that
registers it (`hystkit.cli._main._parser`); what that subcommand accepts and shows is the same."""

from __future__ import annotations

import argparse
import contextlib
import io

import pytest

from hystkit.cli import main
from hystkit.cli._main import _named_command, _parser


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


FULL = _subcommands(_parser())


@pytest.mark.parametrize("command", sorted(FULL))
def test_a_named_subcommand_gets_the_same_parser_as_in_the_whole_one(command):
    partial = _subcommands(_parser(command))
    assert command in partial and set(partial) <= set(FULL)
    assert partial[command].format_help() == _subcommands(_parser())[command].format_help()


def test_fit_skips_the_modules_after_its_own():
    assert "fit" in _subcommands(_parser("fit")) and len(_subcommands(_parser("fit"))) < len(FULL)


@pytest.mark.parametrize("argv", [["no-such-command"], ["--version"], [], ["-h"]])
def test_no_known_subcommand_gets_every_subcommand(argv):
    assert set(_subcommands(_parser(_named_command(argv)))) == set(FULL)


def test_the_error_for_an_unknown_subcommand_lists_them_all():
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        assert main(["fitt"]) == 2
    assert all(f"'{name}'" in err.getvalue() for name in FULL)


def test_the_named_command_is_the_first_word_unless_it_is_an_option():
    assert _named_command(["fit", "a.csv", "--size", "2"]) == "fit"
    assert _named_command(["--version"]) is None
    assert _named_command([]) is None
