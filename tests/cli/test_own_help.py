"""Every argument of fit, evaluate and compensate explains itself; fit's pl options (issue 11)."""

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


@pytest.mark.parametrize("command", ["fit", "evaluate", "compensate"])
def test_every_argument_has_help(command):
    sub = _subparser(command)
    sub.format_help()  # resolves the deferred help texts
    missing = [a.dest for a in sub._actions
               if not isinstance(a, argparse._HelpAction)
               and (a.help is None or a.help == argparse.SUPPRESS or not str(a.help).strip())]
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
