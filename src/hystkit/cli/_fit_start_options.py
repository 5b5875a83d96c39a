"""The reference document's own fitting setups as ``hystkit fit`` options (issue 14.4).

* ``--init SPEC``: start the fit from one given parameter set, and from it only (the
  document's fmincon procedure, table 5.2). ``SPEC`` is JSON (``'{"i_s": 0.1, "v_t": 0.2,
  "w": [1, 0.4], "v_b": -0.6}'``), a ``key=value`` list (``i_s=0.1,v_t=0.2,w=1:0.4,v_b=-0.6``:
  pairs separated by ``,``, list entries by ``:``, rows of a matrix by ``;``), or the name of
  one of the family's presets (``table-5.2``); ``--init list`` lists the presets of
  ``--model``. Keys are the
  family's parameter names, case-insensitive (``I_S`` = ``i_s``); a single value is repeated
  over the cells. Values are in normalised units (eq. 5.10).
* ``--no-limit``: the model without the stability limit eq. 5.29 (the unbounded sinh of sec.
  5.3.3), for reproducing its divergence; a warning says so.
* ``--weight-sum-max B``: the document's constraint ``sum |w_k| <= B`` (it used 100).

This module adds the options (light: building the parser loads nothing heavy);
`hystkit.cli._fit_checks` turns them into a fit's options.
"""

from __future__ import annotations

import argparse

from ._option_types import number

__all__ = ["add_start_options"]

class _InitSpec(argparse.Action):
    """``--init SPEC``; ``--init list`` is resolved after parsing
    (`hystkit.cli._fit_checks.list_presets`), when ``--model`` is known wherever it stands, and
    needs neither recordings nor ``--out``."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        if values == "list":
            # this parser is built for one command line: only the listing runs on it
            for action in parser._actions:
                action.required = False


def add_start_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--init``, ``--no-limit`` and ``--weight-sum-max`` to the ``fit`` parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The ``fit`` subcommand's parser.
    """
    parser.add_argument(
        "--init", action=_InitSpec, default=None, metavar="SPEC",
        help="start the fit from these parameters only (the document's single fmincon start, "
             "normalised units): JSON '{\"i_s\": 0.1, \"v_t\": 0.2, \"w\": [1, 0.4], \"v_b\": "
             "-0.6}', a list i_s=0.1,v_t=0.2,w=1:0.4,v_b=-0.6 (one value is repeated over the "
             "cells) or the name of one of --model's presets ('--init list' lists them); for "
             "the families that declare a start from given parameters (given for another, "
             "the error names them)")
    parser.add_argument(
        "--no-limit", action="store_true",
        help="families whose structure has the stability limit eq. 5.29 (given for another, "
             "the error names them): drop it (the unbounded model of sec. 5.3.3), to "
             "reproduce the document's diverging fits; not for use")
    parser.add_argument(
        "--weight-sum-max", type=number(0, low_open=True), default=None, metavar="B",
        help="families that declare a weight-sum floor (given for another, the error names "
             "them): constrain sum |w_k| <= B, B above the family's floor, as the document's "
             "fmincon fit (B = 100; default: no constraint beyond the box |w_k| <= 100)")
