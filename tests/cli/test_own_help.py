"""Every argument of every subcommand explains itself; fit's pl options (issue 11)."""

from __future__ import annotations

import argparse
import json

import pytest

from hystkit.cli import main
from hystkit.cli._main import _parser


def _subparser(name: str) -> argparse.ArgumentParser:
    parser = _parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices[name]


def _all_subparsers(parser: argparse.ArgumentParser, prefix: str = ""):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield f"{prefix}{name}", sub
                yield from _all_subparsers(sub, f"{prefix}{name} ")


COMMANDS = [name for name, _ in _all_subparsers(_parser())]


@pytest.mark.parametrize("command", COMMANDS)
def test_every_argument_has_help(command):
    sub = dict(_all_subparsers(_parser()))[command]
    sub.format_help()  # resolves the deferred help texts
    shown = {a.dest for a in sub._actions if a.help not in (None, argparse.SUPPRESS)}
    missing = [a.dest for a in sub._actions
               if not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))
               and (a.help is None or not str(a.help).strip()
                    # a hidden old spelling (select --jobs) is fine beside the documented one
                    or (a.help == argparse.SUPPRESS and a.dest not in shown))]
    assert missing == []


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("pl") / "rec.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(path)]) == 0
    return path


def test_fit_pl_structure_options_reach_the_model_file(recording, tmp_path, capsys):
    out = tmp_path / "pl.json"
    code = main(["fit", str(recording), "--model", "pl", "--p", "5", "--m", "2", "--s", "0.01",
                 "--out", str(out)])
    assert code in (0, 3), capsys.readouterr().err  # 3: a fit that failed its guards
    structure = json.loads(out.read_text())["structure"]
    assert (structure["power"], structure["n_basis"], structure["smoothing"]) == (5.0, 2, 0.01)
    assert len(json.loads(out.read_text())["params"]["a"]) == 2  # M basis slopes


@pytest.mark.parametrize("argv, fragment", [
    (["--model", "pl", "--p", "5000"], "power p must lie in [1.01, 1000]"),
    (["--model", "pl", "--p", "1"], "--p: must be > 1"),
    (["--model", "pl", "--m", "0"], "--m: must be a whole number in [1, 1000]"),
    (["--model", "pl", "--s", "-1"], "--s: must be >= 0"),
    (["--p", "5"], "--p, --m and --s apply to the pl model only, not 'mpl'"),
])
def test_fit_pl_options_are_checked_before_work(recording, tmp_path, capsys, argv, fragment):
    capsys.readouterr()
    code = main(["fit", str(recording), *argv, "--out", str(tmp_path / "m.json")])
    out, err = capsys.readouterr()
    assert code == 2 and fragment in err and out == ""
    assert not (tmp_path / "m.json").exists()
