"""The help of ``fit``'s family-specific options names no family (issue 28.4): which families
take an option is what they declare (`hystkit.models.Family.capabilities`, the structure's
knobs), and the error for another family names them; a hand-written list would go stale when
a family (or a plugin) is added."""

from __future__ import annotations

import argparse
import re

import pytest

from hystkit.cli import main
from hystkit.cli._main import _parser
from hystkit.models import FAMILY_INFO

FAMILY_OPTIONS = ("--slope-cap", "--init", "--no-limit", "--weight-sum-max", "--loss")


def _fit_help(option: str) -> str:
    sub = next(a for a in _parser("fit")._actions if isinstance(a, argparse._SubParsersAction))
    fit = sub.choices["fit"]
    fit.format_help()  # computes the deferred values
    return next(a.help for a in fit._actions if option in a.option_strings)


@pytest.mark.parametrize("option", FAMILY_OPTIONS)
def test_a_family_option_s_help_names_no_family(option):
    words = set(re.findall(r"[\w.-]+", _fit_help(option)))
    assert "famil" in _fit_help(option)  # it says whose option it is
    assert not words & set(FAMILY_INFO), option


@pytest.mark.parametrize("argv, takers", [
    (["--model", "pi", "--no-limit"], "(mpl, mpl-poly)"),
    (["--model", "pi", "--slope-cap", "0.5"], "(chua, ladder, mpl, mpl-g, mpl-poly, pl)"),
])
def test_the_error_names_the_families_that_take_it(tmp_path, capsys, argv, takers):
    data = tmp_path / "r.csv"
    data.write_text("time,position,sensor\n0,0,0\n0.025,1,1\n")
    assert main(["fit", str(data), "--out", str(tmp_path / "m.json"), *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("hystkit: error: ") and takers in err and len(err.splitlines()) == 1
