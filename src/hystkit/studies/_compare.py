"""Every model family on the same recordings: ``hystkit compare`` (``hystkit generalize`` is
:mod:`._generalize`, its figure :mod:`._generalization_plot`).

The document chose its model by argument (table 2.1); here each family is fitted and scored on
the same data, with table 2.1's properties measured on the fitted model.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from ..compensation import (
    centre_and_scale,
    check_excursion,
    check_fitting_data,
    evaluate,
    fit_compensator,
    use_verdict,
)
from ..errors import HystkitError
from ..io import Recording
from ..metrics import e_max_pct, e_rms_pct, r2
from ..models import FAMILIES, get_family
from ..parallel import Executor, SerialExecutor, fit_cost
from ._properties import measure_properties

__all__ = ["DISQUALIFYING", "FAMILY_FAILURES", "compare_models", "format_compare"]


# What a failing family can raise: our own errors, the numerical ones of a fit gone
# degenerate (e.g. a collapsed model whose properties cannot be measured), and whatever else
# one family's code raises on odd data: one family never takes the others down.
FAMILY_FAILURES = (Exception,)
# Fit statuses (compensation guards) that make a model unusable, not merely suspicious.
DISQUALIFYING = ("collapsed", "no_signal", "worse_than_line")


def _forward_scores(name: str, size: int | None, fit_rec: Recording,
                    val_rec: Recording) -> dict:
    """Fit position -> sensor; score the forward prediction and the inverse on validation.

    The inverse is scored twice: deployable (the fitting recording's offsets) and oracle (the
    validation recording's own means, the paper's protocol).
    """
    family = get_family(name)
    scaling, s_fit, p_fit = centre_and_scale(fit_rec, "fit")
    structure = family.make_structure(fit_rec.dt, structure_size(family, size))
    check_fitting_data([fit_rec], family, structure)
    result = family.fit(p_fit, s_fit, structure)
    offsets = {"": (scaling.sensor_offset, scaling.position_offset),
               "_oracle": (val_rec.sensor.mean(), val_rec.position.mean())}
    out = {"size": structure_size(family, size), "size_help": family.size_help,
           "n_params": _count_numbers(result.params.to_dict()), "fit_seconds": result.seconds,
           "converged": result.converged, "compensated_note": ""}
    for suffix, (s_off, p_off) in offsets.items():
        s_val = (val_rec.sensor - s_off) / scaling.sensor_scale
        p_val = (val_rec.position - p_off) / scaling.position_scale
        s_hat, _ = family.simulate(structure, result.params, p_val)
        out[f"r2_forward{suffix}"] = r2(s_val, s_hat)
        if suffix == "":
            out["e_rms_pct"] = e_rms_pct(s_val, s_hat, scale=1.0)
            out["e_max_pct"] = e_max_pct(s_val, s_hat, scale=1.0)
        out[f"r2_compensated{suffix}"] = None
        if family.invert is None:
            out["compensated_note"] = family.no_inverse_reason
            continue
        try:
            p_hat, _ = family.invert(structure, result.params, s_val)
            out[f"r2_compensated{suffix}"] = r2(p_val, p_hat)
        except HystkitError as exc:
            out["compensated_note"] = f"inverse failed: {exc}"
    try:
        out.update(measure_properties(family, structure, result.params))
    except FAMILY_FAILURES as exc:
        out.update(rate_dependent=None, return_point_memory=None, minor_loops_close=None,
                   properties_note=f"not measurable: {exc}")
    return out


def structure_size(family, size: int | None) -> int:
    return family.default_size if size is None else size


def _count_numbers(tree) -> int:
    """Fitted numbers in a params dict (nested lists and scalars)."""
    if isinstance(tree, dict):
        return sum(_count_numbers(v) for v in tree.values())
    if isinstance(tree, list | tuple):
        return sum(_count_numbers(v) for v in tree)
    return 1 if isinstance(tree, int | float) and not isinstance(tree, bool) else 0


def compare_models(fit_rec: Recording, val_rec: Recording, models: Sequence[str] | None = None,
                   sizes: Mapping[str, int] | None = None,
                   progress: Callable[[str], None] = lambda _: None,
                   executor: Executor | None = None) -> dict:
    """Fit every model on ``fit_rec`` and score it on ``val_rec``.

    Each family is one piece of work for `executor` (default: serial): its forward model and
    its direct compensator; the table is the same whichever executor ran them.

    Parameters
    ----------
    fit_rec : Recording
        The recording every family is fitted on.
    val_rec : Recording
        The recording every fit is scored on.
    models : sequence of str, optional
        Family names; None: every registered family (``hystkit.models.FAMILIES``), sorted.
    sizes : mapping of str to int, optional
        Size per family name; a family not in it gets its default size.
    progress : callable, optional
        Called with one line of text as each family is done (default: nothing).
    executor : Executor, optional
        Runs the pieces of work; None: serially, here.

    Returns
    -------
    dict
        ``{model: {n_params, fit_seconds, r2_forward, r2_compensated (None if no inverse, with
        compensated_note), r2_direct (a compensator fitted sensor -> position), linear_r2,
        the same four with an ``_oracle`` suffix (paper's protocol), center, direct_status,
        verdict and verdict_message (the shared verdict on the direct compensator's deployable
        validation scores, :func:`hystkit.compensation.verdict`), e_rms_pct, e_max_pct (forward, % of the normalised range), rate_dependent,
        return_point_memory, minor_loops_close, ...}}``, in the order of `models`; a model
        whose fit fails has ``error`` (the others are still scored).

    Raises
    ------
    InputError
        Fitting data no family can be fitted to (too short, constant, a spike), or validation
        data no family can be scored on (constant, a spike); checked once before any fit. Too
        few samples for one family's parameters is that family's error.
    """
    check_fitting_data([fit_rec])
    check_excursion([val_rec])
    models = sorted(FAMILIES) if models is None else list(models)
    # One piece per family, its two fits together: a worker then loads one family's compiled
    # kernels once, where two pieces of the same family on two workers loaded them twice.
    pieces = [(name, (sizes or {}).get(name)) for name in models]
    n_done = 0

    def done(i: int, _: dict) -> None:
        nonlocal n_done
        n_done += 1
        progress(f"  {pieces[i][0]}: fitted and scored ({n_done}/{len(models)})")

    results = (executor or SerialExecutor()).map(
        _compare_family, pieces, shared={"fit_rec": fit_rec, "val_rec": val_rec},
        on_done=done, cost=lambda piece: 2 * fit_cost(piece[0], piece[1], fit_rec.sensor.size))
    return dict(zip(models, results, strict=True))


def _compare_family(piece: tuple[str, int | None], *, fit_rec: Recording,
                    val_rec: Recording) -> dict:
    """One family's forward scores and its direct compensator's, or the first ``error``
    (the forward fit's, as when the two ran one after the other)."""
    name, size = piece
    forward, direct = (_compare_piece((name, size, part), fit_rec=fit_rec, val_rec=val_rec)
                       for part in ("forward", "direct"))
    return next((part for part in (forward, direct) if "error" in part),
                {**forward, **direct})


def _compare_piece(piece: tuple[str, int | None, str], *, fit_rec: Recording,
                   val_rec: Recording) -> dict:
    """One family's forward scores or its direct compensator's; a failure is an ``error``."""
    name, size, part = piece
    try:
        if part == "forward":
            return _forward_scores(name, size, fit_rec, val_rec)
        comp = fit_compensator(fit_rec, size, model=name, diagnose=False)
        direct = evaluate(comp, val_rec)
        use, why = use_verdict(direct, "validation (deployable)")
        entry = {"center": direct["center"], "direct_status": comp.fit_info["status"],
                 "verdict": use, "verdict_message": why}
        for suffix in ("", "_oracle"):
            entry[f"r2_direct{suffix}"] = direct[f"r2{suffix}"]
            entry[f"linear_r2{suffix}"] = direct[f"linear_r2{suffix}"]
        return entry
    except FAMILY_FAILURES as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}


def _fmt(x: float | None, spec: str = ".4f") -> str:
    # the leading space keeps a value wider than its column (R² -2390.9675) apart from the next
    return " -" if x is None else " " + format(x, spec)


def _yes_no(flag: bool | None) -> str:
    return "n/a" if flag is None else ("yes" if flag else "no")


def format_compare(table: Mapping[str, dict]) -> str:
    """Plain-text table of :func:`compare_models`' result: deployable, then oracle scores.

    Parameters
    ----------
    table : mapping of str to dict
        :func:`compare_models`' result.

    Returns
    -------
    str
        One line per model (``FAILED`` and its error for a failed one), then why R² inv is
        missing where it is.
    """
    head = (f"{'model':<10}{'params':>7}{'fit s':>7}{'R² fwd':>8}{'R² inv':>8}{'R² dir':>8}"
            f"{'line':>8} | oracle:{'R² inv':>8}{'R² dir':>8}{'line':>8}{'e_rms%':>8}"
            f"  rate-dep  ret.point  minor  direct fit  verdict on validation")
    lines = [head]
    for name, m in table.items():
        if "error" in m:
            lines.append(f"{name:<10}  FAILED: {m['error']}")
            continue
        lines.append(
            f"{name:<10}{_fmt(m['n_params'], 'd'):>7}{_fmt(m['fit_seconds'], '.2f'):>7}"
            f"{_fmt(m['r2_forward']):>8}{_fmt(m['r2_compensated']):>8}{_fmt(m['r2_direct']):>8}"
            f"{_fmt(m['linear_r2']):>8} |        {_fmt(m['r2_compensated_oracle']):>8}"
            f"{_fmt(m['r2_direct_oracle']):>8}{_fmt(m['linear_r2_oracle']):>8}"
            f"{_fmt(m['e_rms_pct'], '.2f'):>8}"
            f"  {_yes_no(m['rate_dependent']):>8}  {_yes_no(m['return_point_memory']):>9}"
            f"  {_yes_no(m['minor_loops_close']):>5}  {m['direct_status']:<10}"
            f"  {m.get('verdict', 'n/a')}")
    notes = [f"  {name}: no R² inv: {m['compensated_note']}" for name, m in table.items()
             if "error" not in m and m["r2_compensated"] is None]
    return "\n".join(lines + (["why some R² inv are missing:"] + notes if notes else []))
