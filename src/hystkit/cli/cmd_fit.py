"""``hystkit fit``: fit one named model to recordings and write it (the guided fit,
``--model auto``, is `hystkit.cli._guided_fit`)."""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace

from ..compensation import (
    MODEL_SUFFIXES,
    center_label,
    fit_compensator,
    save_compensator,
    with_band,
)
from ..io import check_output_path, training_reading, training_units
from ..models import get_family
from ._commands import resolve
from ._common import GUARD_EXIT, UsageError, check_size, say_next
from ._core_options import DEFAULT_MODEL, GUIDED_MODEL, model_options_given
from ._fit_checks import (
    FitOptions,
    cost_options,
    list_presets,
    start_options,
    structure_options,
    structure_takers,
    structure_takes,
    weight_sum_options,
)
from ._fit_report import FitReport, units_label
from ._inputs import check_inputs_exist
from ._next_step import next_step

__all__ = ["fit_named", "has_slope_cap", "run_fit"]


def run_fit(args: argparse.Namespace) -> int:
    """``hystkit fit``: one named model, or the guided fit (``--model auto``)."""
    opts = FitOptions.from_args(args, _chosen_model(args))
    if opts.model == GUIDED_MODEL:
        return resolve("_guided_fit:run_guided_fit")(opts)
    return fit_named(opts)


def fit_named(opts: FitOptions) -> int:
    """``hystkit fit --model NAME``: one fit, its band, the model file and the report."""
    if opts.budget is not None:
        raise UsageError(f"--budget applies to --model {GUIDED_MODEL} (a named model is one "
                         f"fit, not a selection)")
    if opts.init == "list":
        return list_presets(opts)
    check_inputs_exist(opts.data)
    check_output_path(opts.out, opts.force, inputs=opts.data, formats=MODEL_SUFFIXES,
                      what="a model file")
    family = get_family(opts.model)
    costs = cost_options(opts)
    constraint = weight_sum_options(opts, family)
    options = {} if opts.slope_cap is None else {"slope_cap": opts.slope_cap}
    if options and not has_slope_cap(family):
        raise UsageError(f"--slope-cap applies to the models with an Euler slope cap "
                         f"({', '.join(structure_takers('slope_cap'))}), not {opts.model!r}")
    options.update(_pl_options(opts, family))
    options.update(structure_options(opts, family))
    check_size(opts.model, opts.cells, "--cells")
    reading, recs = opts.reader.training_files(opts.data)
    size = family.default_size if opts.cells is None else opts.cells
    fit_options = {**start_options(opts, family, recs[0].dt, size, options), **constraint}
    shown = "".join(f", {name} {str(value).lower() if isinstance(value, bool) else f'{value:g}'}"
                    for name, value in options.items())
    print(f"fitting {opts.model} ({family.size_help}: {size}{shown}, {opts.mode} mode, centring: "
          f"{center_label(opts.center)}) on {', '.join(map(str, opts.data))}: "
          f"{sum(r.n_samples for r in recs)} samples at {recs[0].fs:g} Hz"
          f"{units_label(recs[0])} ...", flush=True)
    fit_arguments = {"tare_seconds": opts.tare_seconds, "track_seconds": opts.track_seconds,
                     **costs.fit_arguments(opts, recs), "fit_options": fit_options, **options}
    comp = fit_compensator(recs, size, model=opts.model, mode=opts.mode, center=opts.center,
                           **fit_arguments)
    passed = comp.fit_info["status"] == "ok"
    if not opts.no_band and passed:
        # the band's folds refit the same model: only for a model that may be used
        comp = with_band(comp, recs, size, fit_arguments, level=opts.level)
    notes = {} if opts.no_band or passed else {"band": "no band: the fit did not pass its guards"}
    units = training_units(recs)
    notes.update({"units": units} if units else {})
    remembered, not_remembered = training_reading(reading, opts.data, units)
    # a new record, not an edit of the fitted one; later commands read files of this layout
    comp = replace(comp, reading=remembered, fit_info={**comp.fit_info, **notes})
    save_compensator(comp, opts.out, force=opts.force)
    info = comp.fit_info
    print(f"done in {info['fit_seconds']:.2f} s: SSE {info['cost']:.4g} (normalised), solver: "
          f"{info['message']}")
    print(FitReport.of(comp, notes=tuple(filter(None, [not_remembered]))).text())
    print(f"wrote {opts.out}")
    if info["status"] != "ok":
        print(f"hystkit: fit {info['status'].replace('_', ' ')}: {info['status_message']}; the "
              f"model was written for inspection, do not use it as a compensator",
              file=sys.stderr)
        say_next(next_step(info["status"], model=opts.model, size=size, mode=opts.mode,
                           line_r2=info["training_linear_r2"]))
        return GUARD_EXIT
    print(f"  status: ok ({info['status_message']})")
    return 0


def _chosen_model(args: argparse.Namespace) -> str:
    """``--model``, or without it `DEFAULT_MODEL`; mpl when an option of a named model is
    given (``--cells 3`` alone is the 3-cell mpl, whatever the default)."""
    if args.model is not None:
        return args.model
    return "mpl" if model_options_given(args) else DEFAULT_MODEL


def has_slope_cap(family) -> bool:
    """Whether the family's structure takes an Euler slope cap (``make_structure(...,
    slope_cap=...)``)."""
    return structure_takes(family, "slope_cap")


def _pl_options(opts: FitOptions, family) -> dict:
    """``--p``, ``--m``, ``--s`` of the pl model as structure options, checked by the family
    before any work (one line naming the option)."""
    given = {name: value for name, value in (("power", opts.p), ("n_basis", opts.m),
                                             ("smoothing", opts.s)) if value is not None}
    if not given:
        return {}
    if not structure_takes(family, *given):
        takers = structure_takers(*given)
        raise UsageError(f"--p, --m and --s apply to the {', '.join(takers)} model"
                         f"{'s' if len(takers) > 1 else ''} only, not {opts.model!r}")
    size = family.default_size if opts.cells is None else opts.cells
    try:
        family.make_structure(1 / 40, size, **given)
    except ValueError as exc:
        raise UsageError(f"--p/--m/--s: {exc}") from None
    return given
