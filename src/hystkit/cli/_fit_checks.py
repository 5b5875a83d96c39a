"""``hystkit fit``'s start, structure and cost options checked against the family to fit
and turned into its fit's options (issue 14.4): ``--init`` (and ``--init list``),
``--no-limit``, ``--weight-sum-max``, ``--loss``, ``--f-scale``, ``--weights``. The options
themselves are added by `hystkit.cli._fit_start_options` and `hystkit.cli._fit_cost_options`.
"""

from __future__ import annotations

import argparse
import inspect
import json
import sys
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from ..compensation import check_loss_available
from ..errors import InputError
from ..io import read_other_columns
from ..models import FAMILIES, get_family
from ._option_types import UsageError
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["CostOptions", "FitOptions", "cost_options", "list_presets", "parse_init",
           "start_options", "structure_options", "structure_takers", "structure_takes",
           "weight_sum_options"]



@dataclass(frozen=True)
class FitOptions:
    """What ``hystkit fit`` was asked, as parsed (each value checked by its option's type);
    the checks against the family to fit are this module's functions."""

    data: tuple[Path, ...]  # empty only for --init list
    out: Path | None  # None only for --init list
    force: bool
    model: str  # the family, or the guided fit's name
    budget: float | None
    cells: int | None
    mode: str
    center: str
    tare_seconds: float
    track_seconds: float
    slope_cap: float | None
    p: float | None
    m: int | None
    s: float | None
    level: float
    no_band: bool
    init: str | None
    no_limit: bool
    weight_sum_max: float | None
    loss: str
    f_scale: float | None
    weights: str | None
    reader: Reader  # the recordings' reading options

    @classmethod
    def from_args(cls, args: argparse.Namespace, model: str) -> FitOptions:
        """The options of a parsed ``fit`` command line, fitting `model`."""
        named = {f.name for f in fields(cls)} - {"data", "model", "reader"}
        return cls(data=tuple(args.data or ()), model=model,
                   reader=Reader(given_read_options(args)),
                   **{name: getattr(args, name) for name in named})


_NO_LIMIT_WARNING = ("hystkit: warning: --no-limit: {model} without the stability limit "
                     "(eq. 5.29) can diverge (sec. 5.3.3; paper 9.2: its chirp model without "
                     "the limits is unstable); this fit reproduces the document's for study, "
                     "not for use as a compensator")
_DEFAULT_F_SCALE_WARNING = ("hystkit: warning: --loss {loss} without --f-scale: f_scale 1 "
                            "leaves a robust loss close to the SSE on the normalised data "
                            "(max |.| = 1); set --f-scale to 5-10 times the plain fit's RMS "
                            "residual")



def list_presets(opts: FitOptions) -> int:
    """Print the presets of ``opts.model`` (``--init list``).

    Parameters
    ----------
    opts : FitOptions
        Parsed ``fit`` arguments with ``init == "list"``.

    Returns
    -------
    int
        The exit code, 0.
    """
    family = get_family(opts.model)
    presets = family.presets()
    if not presets:
        print(f"{family.name} has no presets")
    for name, (structure, params, info) in presets.items():
        print(f"{name}: {info.get('source', '')}\n  {params.to_dict()}")
    return 0


def structure_takes(family: Any, *keywords: str) -> bool:
    """Whether `family`'s structure takes every one of `keywords` (``make_structure(...,
    slope_cap=...)``): the knobs the family declares."""
    return set(keywords) <= set(inspect.signature(family.make_structure).parameters)


def structure_takers(*keywords: str) -> list[str]:
    """The registered families whose structure takes every one of `keywords` (for the error
    that refuses an option: every family loads)."""
    return [name for name, family in FAMILIES.items() if structure_takes(family, *keywords)]


def structure_options(opts: FitOptions, family: Any) -> dict:
    """The structure options of ``--no-limit``, its warning printed on stderr.

    Parameters
    ----------
    opts : FitOptions
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
    if not opts.no_limit:
        return {}
    if not structure_takes(family, "limit"):
        raise UsageError(f"--no-limit applies to models with the stability limit eq. 5.29 "
                         f"({', '.join(structure_takers('limit'))}), not {family.name!r}")
    print(_NO_LIMIT_WARNING.format(model=family.name), file=sys.stderr)
    return {"limit": False}


def weight_sum_options(opts: FitOptions, family: Any) -> dict:
    """The fit option of ``--weight-sum-max``, checked before any data are read.

    Parameters
    ----------
    opts : FitOptions
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
    if opts.weight_sum_max is None:
        return {}
    _check_takes(family, "weight_sum_max", "--weight-sum-max")
    if len(opts.data) > 1:
        raise UsageError("--weight-sum-max applies to a fit on one recording (the joint "
                         "polish of several is unconstrained)")
    if opts.loss not in (None, "linear"):
        raise UsageError("--weight-sum-max is solved on the SSE (eq. 5.9), not with --loss")
    floor = family.capabilities.weight_sum_floor
    if not opts.weight_sum_max > floor:
        raise UsageError(f"--weight-sum-max for {family.name} must be above {floor:g} (its "
                         f"fit's gauge fixes w_0 = 1), got {opts.weight_sum_max:g}")
    return {"weight_sum_max": opts.weight_sum_max}


def start_options(opts: FitOptions, family: Any, dt: float, size: int,
                  options: dict) -> dict:
    """Fit options of ``--init`` for ``family.fit``; prints a note for every start value the
    fit's box moves.

    Parameters
    ----------
    opts : FitOptions
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
    if opts.init is None:
        return {}
    _check_takes(family, "init", "--init")
    try:
        structure = family.make_structure(dt, size, **options)
    except (ValueError, TypeError) as exc:
        raise InputError(f"model {family.name!r}: {exc}") from None
    try:
        start = family.start_options(structure, parse_init(opts.init, family, structure))
    except InputError:  # already one line naming --init
        raise
    except ValueError as exc:  # e.g. mpl-g's gauge needs w_0 != 0
        raise InputError(f"--init: {exc}") from None
    for note in start.clipped:
        print(f"  --init: {note}")
    return dict(start.options)


def _check_takes(family: Any, keyword: str, option: str) -> None:
    if keyword not in family.fit_options:
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


@dataclass(frozen=True)
class CostOptions:
    """The cost a ``fit`` command asked for, checked against its model."""

    loss: str = "linear"
    f_scale: float = 1.0
    weights: str | None = None

    def fit_arguments(self, opts: FitOptions, recs: list) -> dict:
        """Keyword arguments of `hystkit.compensation.fit_compensator` for the recordings
        `recs` read from ``opts.data`` (the weights column read with the same read options);
        empty for the plain SSE."""
        out: dict = {}
        if self.loss != "linear":
            out.update(loss=self.loss, f_scale=self.f_scale)
        if self.weights is not None:
            out["weights"] = self.weights
            out["other_columns"] = [
                read_other_columns(path, rec.n_samples, opts.reader.options(Path(path)))
                for path, rec in zip(opts.data, recs, strict=True)]
        return out


def cost_options(opts: FitOptions) -> CostOptions:
    """The parsed cost options, refused in one line (before any work) where they do not apply.

    A robust ``--loss`` without ``--f-scale`` runs with scipy's f = 1 and a warning on stderr:
    on data normalised to max |.| = 1 that leaves the loss close to the SSE.

    Parameters
    ----------
    opts : FitOptions
        Parsed ``fit`` arguments (``model``, ``loss``, ``f_scale``, ``weights``,
        ``weight_sum_max``).

    Returns
    -------
    CostOptions
        The cost to fit with.

    Raises
    ------
    UsageError
        ``--f-scale`` without a robust loss, an empty ``--weights``, or ``--weights`` with
        ``--weight-sum-max``.
    InputError
        A robust loss for a model fitted by linear least squares
        (:func:`hystkit.compensation._fitting.check_loss_available`).
    """
    if opts.f_scale is not None and opts.loss == "linear":
        raise UsageError("--f-scale applies to a robust --loss (soft_l1, huber, cauchy), not "
                         "to linear (the SSE)")
    f_scale = 1.0 if opts.f_scale is None else opts.f_scale
    check_loss_available(opts.model, opts.loss, f_scale)
    if opts.weights is not None and not opts.weights.strip():
        raise UsageError("--weights needs a column name")
    if opts.weights is not None and opts.weight_sum_max is not None:
        raise UsageError("--weight-sum-max is solved on the SSE (eq. 5.9), not with --weights")
    if opts.loss != "linear" and opts.f_scale is None:
        print(_DEFAULT_F_SCALE_WARNING.format(loss=opts.loss), file=sys.stderr)
    return CostOptions(loss=opts.loss, f_scale=f_scale, weights=opts.weights)
