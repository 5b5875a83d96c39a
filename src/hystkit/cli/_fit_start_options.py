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

Heavy imports (numpy, the families) stay inside the functions: building the parser loads none.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from ..errors import InputError
from ._common import UsageError, number

__all__ = ["add_start_options", "list_presets", "parse_init", "start_options",
           "structure_options", "weight_sum_options"]

_NO_LIMIT_WARNING = ("hystkit: warning: --no-limit: {model} without the stability limit "
                     "(eq. 5.29) can diverge (sec. 5.3.3; paper 9.2: its chirp model without "
                     "the limits is unstable); this fit reproduces the document's for study, "
                     "not for use as a compensator")


class _InitSpec(argparse.Action):
    """``--init SPEC``; ``--init list`` is resolved after parsing (:func:`list_presets`), when
    ``--model`` is known wherever it stands, and needs neither recordings nor ``--out``."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        if values == "list":
            # this parser is built for one command line: only the listing runs on it
            for action in parser._actions:
                action.required = False


def list_presets(args: argparse.Namespace) -> int:
    """Print the presets of ``args.model`` (``--init list``).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed ``fit`` arguments with ``init == "list"``.

    Returns
    -------
    int
        The exit code, 0.
    """
    from ..models import get_family

    family = get_family(args.model)
    presets = family.presets()
    if not presets:
        print(f"{family.name} has no presets")
    for name, (structure, params, info) in presets.items():
        print(f"{name}: {info.get('source', '')}\n  {params.to_dict()}")
    return 0


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
             "cells) or a preset name (mpl: table-5.2, table-5.2-fitted, paper-9.1; mpl-poly: "
             "paper-9.2-table-i; mpl-g: ch7-table-ii-sine, -chirp, -decay, -noise); "
             "'--init list' lists the presets of --model; mpl, mpl-poly, mpl-g")
    parser.add_argument(
        "--no-limit", action="store_true",
        help="mpl, mpl-poly: drop the stability limit eq. 5.29 (the unbounded sinh or cubic "
             "of sec. 5.3.3), to reproduce the document's diverging fits; not for use")
    parser.add_argument(
        "--weight-sum-max", type=number(0, low_open=True), default=None, metavar="B",
        help="mpl, mpl-g: constrain sum |w_k| <= B as the document's fmincon fit (B = 100; "
             "default: no constraint beyond the box |w_k| <= 100); mpl-g counts w_0 = 1 of its "
             "gauge")


def structure_options(args: argparse.Namespace, family: Any) -> dict:
    """The structure options of ``--no-limit``, its warning printed on stderr.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed ``fit`` arguments (``no_limit``).
    family : Family
        The family to fit (its ``make_structure`` must take ``limit``).

    Returns
    -------
    dict
        ``{"limit": False}`` for ``--no-limit``, else ``{}``.

    Raises
    ------
    UsageError
        If the family has no stability limit to drop.
    """
    if not args.no_limit:
        return {}
    import inspect

    if "limit" not in inspect.signature(family.make_structure).parameters:
        raise UsageError(f"--no-limit applies to models with the stability limit eq. 5.29 "
                         f"(mpl, mpl-poly), not {family.name!r}")
    print(_NO_LIMIT_WARNING.format(model=family.name), file=sys.stderr)
    return {"limit": False}


def weight_sum_options(args: argparse.Namespace, family: Any) -> dict:
    """The fit option of ``--weight-sum-max``, checked before any data are read.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed ``fit`` arguments (``data``, ``loss``, ``weight_sum_max``).
    family : Family
        The family to fit.

    Returns
    -------
    dict
        ``{"weight_sum_max": B}``, or ``{}`` without the option.

    Raises
    ------
    UsageError
        If the family's fit takes no such constraint, several recordings or a robust loss
        come with it, or the bound is not above the family's floor (mpl-g: 1, its gauge's
        ``w_0``).
    """
    if args.weight_sum_max is None:
        return {}
    from ..compensation._fitting import fit_module_constant

    _check_takes(family, "weight_sum_max", "--weight-sum-max")
    if len(args.data) > 1:
        raise UsageError("--weight-sum-max applies to a fit on one recording (the joint "
                         "polish of several is unconstrained)")
    if getattr(args, "loss", None) not in (None, "linear"):
        raise UsageError("--weight-sum-max is solved on the SSE (eq. 5.9), not with --loss")
    floor = fit_module_constant(family.name, "WEIGHT_SUM_FLOOR", 0.0)
    if not args.weight_sum_max > floor:
        raise UsageError(f"--weight-sum-max for {family.name} must be above {floor:g} (its "
                         f"fit's gauge fixes w_0 = 1), got {args.weight_sum_max:g}")
    return {"weight_sum_max": args.weight_sum_max}


def start_options(args: argparse.Namespace, family: Any, dt: float, size: int,
                  options: dict) -> dict:
    """Fit options of ``--init`` for ``family.fit``; prints a note for every start value the
    fit's box moves.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed ``fit`` arguments.
    family : Family
        The family to fit.
    dt : float
        Sample time of the recordings [s].
    size : int
        The family's size knob.
    options : dict
        Structure options (``slope_cap``, ``limit``): with `dt` and `size` they give the
        structure the fit will use, which sizes the ``--init`` values.

    Returns
    -------
    dict
        Keyword options of the family's fit.

    Raises
    ------
    UsageError
        If the family's fit takes no start.
    InputError
        If ``--init`` cannot be read (one line naming what is wrong).
    """
    if args.init is None:
        return {}
    _check_takes(family, "init", "--init")
    try:
        structure = family.make_structure(dt, size, **options)
    except (ValueError, TypeError) as exc:
        raise InputError(f"model {family.name!r}: {exc}") from None
    try:
        start = family.start_options(structure, parse_init(args.init, family, structure))
    except InputError:  # already one line naming --init
        raise
    except ValueError as exc:  # e.g. mpl-g's gauge needs w_0 != 0
        raise InputError(f"--init: {exc}") from None
    for note in start.clipped:
        print(f"  --init: {note}")
    return dict(start.options)


def _check_takes(family: Any, keyword: str, option: str) -> None:
    if keyword not in family.fit_options:
        from ..models import FAMILIES

        takers = [name for name in FAMILIES if keyword in FAMILIES[name].fit_options]
        raise UsageError(f"{option} applies to {', '.join(takers)}, not {family.name!r}")


def parse_init(text: str, family: Any, structure: Any) -> Any:
    """The parameters ``--init`` gives, for ``structure``'s size.

    Parameters
    ----------
    text : str
        JSON object, ``key=value`` list or preset name (see the module docstring).
    family : Family
        The family (its ``Params``, ``presets`` and ``random_params``, whose draw gives the
        shape of every parameter).
    structure : Structure
        The structure the parameters are for.

    Returns
    -------
    Params
        The family's parameters.

    Raises
    ------
    InputError
        If the text is neither, a key is missing or unknown, a value has the wrong number of
        entries, or the values leave the family's parameter domain.
    """
    import numpy as np

    shapes = {name: np.shape(value) for name, value
              in family.random_params(structure, np.random.default_rng(0)).to_dict().items()}
    given = _read_spec(text.strip(), family)
    by_name = {name.lower(): name for name in shapes}
    values: dict[str, Any] = {}
    for key, value in given.items():
        name = by_name.get(str(key).lower())
        if name is None:
            raise InputError(f"--init: {family.name} has no parameter {key!r}; it needs "
                             f"{', '.join(shapes)}")
        values[name] = value
    missing = [name for name in shapes if name not in values]
    if missing:
        raise InputError(f"--init: {family.name} needs {', '.join(shapes)}; missing "
                         f"{', '.join(missing)}")
    for name, shape in shapes.items():
        try:
            array = np.asarray(values[name], dtype=float)
            values[name] = np.broadcast_to(array, shape).copy()
        except (TypeError, ValueError):
            raise InputError(f"--init: {name} = {values[name]!r} does not fit the "
                             f"{structure.n_cells}-cell {family.name}'s shape {shape or 'scalar'}"
                             ) from None
    try:
        return family.Params.from_dict({k: v.tolist() for k, v in values.items()})
    except (ValueError, TypeError, KeyError) as exc:
        raise InputError(f"--init: {exc}") from None


def _read_spec(text: str, family: Any) -> dict:
    if text.startswith(("{", "[", '"')):
        try:
            spec = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError(f"--init: not valid JSON ({exc})") from None
        if not isinstance(spec, dict):
            raise InputError(f"--init: the JSON must be an object of parameter values "
                             f"({{\"name\": value, ...}}), got a {type(spec).__name__}")
        return spec
    if "=" in text:
        return dict(_read_pair(pair) for pair in text.split(",") if pair.strip())
    presets = family.presets()
    if text not in presets:
        names = ", ".join(presets) or "none"
        raise InputError(f"--init: {text!r} is neither JSON, a key=value list nor a preset of "
                         f"{family.name} (presets: {names})")
    return presets[text][1].to_dict()


def _read_pair(pair: str) -> tuple[str, Any]:
    key, sep, value = pair.partition("=")
    if not sep or not key.strip():
        raise InputError(f"--init: expected key=value, got {pair.strip()!r}")
    try:
        rows = [[float(v) for v in row.split(":")] for row in value.split(";")]
    except ValueError:
        raise InputError(f"--init: {key.strip()} = {value!r} is not a number or a "
                         f"':'-separated list of numbers") from None
    if len(rows) > 1:
        return key.strip(), rows
    return key.strip(), rows[0][0] if len(rows[0]) == 1 else rows[0]
