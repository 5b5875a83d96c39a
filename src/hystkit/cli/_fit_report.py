"""What ``fit`` says of a fitted compensator (a named model's and the guided fit's alike): a
frozen `FitReport` read from it once, with one text rendering (lmfit's ``fit_report`` is the
model): the band, what the fit minimised, the parameters as an aligned table with their
standard errors, the scores and the notes."""

from __future__ import annotations

from dataclasses import dataclass

from ..compensation import named_floats
from ..studies import text_table

__all__ = ["MAX_SHOWN", "FitReport", "units_label"]

# Parameters printed by `fit`; a larger model's others are in its file.
MAX_SHOWN = 24


@dataclass(frozen=True)
class FitReport:
    """The report of one fitted compensator, as lines; `text` joins them.

    Built by `of`; a named model's (``criteria``) adds what the fit minimised when that was
    not the plain SSE, AIC and BIC, and a joint fit's note.
    """

    band: tuple[str, ...]
    cost: tuple[str, ...]
    parameters: tuple[str, ...]
    standard_errors: tuple[str, ...]
    scores: str
    notes: tuple[str, ...]

    @classmethod
    def of(cls, comp, *, criteria: bool = True, notes: tuple[str, ...] = ()) -> FitReport:
        """The report of `comp` (its ``fit_info`` as fitted), with the command's `notes`."""
        info = comp.fit_info
        se = info.get("standard_errors")
        scores = (f"  training R² {info['training_r2']:.4f}, straight line "
                  f"{info['training_linear_r2']:.4f}; "
                  + (f"AIC {info['aic']:.1f}, BIC {info['bic']:.1f}; " if criteria else "")
                  + f"sensor polarity {comp.polarity:+g}")
        joint = [f"  {info['joint_fit']}"] if criteria and info.get("joint_fit") else []
        said = [*(info.get("at_model_limits") or ()), *(info.get("redundant") or ()), *notes]
        return cls(band=_band_lines(comp), cost=_cost_lines(info) if criteria else (),
                   parameters=_parameter_lines(comp, se), standard_errors=_se_lines(se),
                   scores=scores, notes=(*joint, *(f"  note: {note}" for note in said)))

    def text(self) -> str:
        return "\n".join([*self.band, *self.cost, *self.parameters, *self.standard_errors,
                          self.scores, *self.notes])


def _parameter_lines(comp, se: dict | None) -> tuple[str, ...]:
    """The fitted parameters as an aligned table (name, value, standard error, relative), as
    lmfit's fit report: n/a where the data do not determine one, 'fixed' where the fit holds
    it (a gauge)."""
    names = [name for name, _ in named_floats(comp.params.to_dict())]
    values = [value for _, value in named_floats(comp.params.to_dict())]
    if se and len(se["standard_errors"]) == len(values):
        fixed = set(se.get("fixed", []))
        errors = ["fixed" if n in fixed else e for n, e in zip(names, se["standard_errors"],
                                                               strict=True)]
        relative = ["" if n in fixed else r for n, r in zip(names, se["relative"], strict=True)]
    else:
        errors = relative = [""] * len(values)

    def g(x: object, digits: int) -> object:  # significant digits, for people
        return f"{x:.{digits}g}" if isinstance(x, float) else ("n/a" if x is None else x)

    rows = [(f"  {n}", g(v, 6), g(e, 2), g(r, 2))
            for n, v, e, r in zip(names, values, errors, relative, strict=True)]
    table = text_table(("  parameter", "value", "std error", "relative"), rows[:MAX_SHOWN])
    if len(rows) > MAX_SHOWN:  # a Preisach grid has 191: the rest is in the model file
        return table, f"  ... {len(rows) - MAX_SHOWN} more parameter(s): see the model file"
    return (table,)


def _se_lines(se: dict | None) -> tuple[str, ...]:
    """One line on the standard errors: the largest relative one, those the data do not
    determine, those the fit holds fixed; and the caveat of a robust or weighted cost."""
    if not se:
        return ()
    rel = [r for r in se["relative"] if r is not None]
    fixed = se.get("fixed", [])  # held fixed by the fit (a gauge): no SE, not undetermined
    n_blind = sum(r is None for r in se["standard_errors"]) - len(fixed)
    worst = f"largest relative SE {max(rel):.3g}" if rel else "no finite SE"
    line = (f"  standard errors (Gauss-Newton, finite-difference Jacobian): {worst}"
            f"{f'; {n_blind} parameter(s) not determined by the data' if n_blind else ''}"
            f"{'; fixed by the fit: ' + ', '.join(fixed) if fixed else ''}")
    # a robust or weighted cost, an active constraint
    return (line, f"    ({se['caveat']})") if se.get("caveat") else (line,)


def _band_lines(comp) -> tuple[str, ...]:
    """The band line: its half-width at the reference rate, or why there is none."""
    note = comp.fit_info.get("band")
    if comp.band is None:
        return (f"  {note}",) if note else ()
    unit = (comp.fit_info.get("units") or {}).get("position", "")
    return ((f"  prediction band {comp.band.level:.0%}: ±{comp.band.quantile():.4g}"
            f"{' ' + unit if unit else ''} at the training rate, wider when faster or outside "
            f"the training range ({note})"),)


def _cost_lines(info: dict) -> tuple[str, ...]:
    """What a fit minimised when that was not the plain SSE (whose value ``fit`` says)."""
    if info.get("criteria_note") is None:
        return ()
    return ((f"  minimised the {info['objective_label']}: {info['objective']:.4g} "
            f"(normalised); R², AIC and BIC are on the plain SSE"),)


def units_label(rec) -> str:
    """`` (position [mm], sensor [Ohm])`` when the file gave units, else ""."""
    shown = ", ".join(f"{name} [{unit}]" for name, unit in rec.units)
    return f" ({shown})" if shown else ""
