"""A command line that names its subcommand builds that subcommand's options only
(`hystkit.cli._main._parser`, from the table `hystkit.cli._commands`); what it accepts and
shows is the same as in the whole parser."""

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


def test_fit_builds_its_own_options_only():
    partial = _subcommands(_parser("fit"))
    with_options = [name for name, p in partial.items() if len(p._actions) > 2]  # -h, --force
    assert with_options == ["fit"] and set(partial) == set(FULL)


@pytest.mark.parametrize("command, options", [
    ("fit", "_core_options"), ("control", "_control_options"),
    ("stability", "_control_options"), ("stream", "_stream_options")])
def test_only_the_chosen_commands_options_module_is_imported(command, options):
    """``hystkit COMMAND --help`` imports that command's options module and no run module
    (checked in a fresh interpreter: this session has imported them all)."""
    import subprocess
    import sys

    probe = ("import contextlib, io, sys\nfrom hystkit.cli import main\n"
             "with contextlib.redirect_stdout(io.StringIO()):\n"
             f"    try:\n        main([{command!r}, '--help'])\n    except SystemExit:\n"
             "        pass\n"
             "print(','.join(sorted(m.rpartition('.')[2] for m in sys.modules\n"
             "                      if m.startswith('hystkit.cli.'))))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, timeout=120).stdout.strip().split(",")
    assert options in out
    others = {"_core_options", "_control_options", "_stream_options", "_study_options",
              "_lab_options"} - {options}
    assert not [m for m in out if m.startswith("cmd_") or m in others], out


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
