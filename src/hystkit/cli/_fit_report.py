"""What ``fit`` prints of a fitted compensator (a named model's and the guided fit's alike): the
band, the parameters as an aligned table with their standard errors, the units."""

from __future__ import annotations

__all__ = ["MAX_SHOWN", "print_band", "print_parameters", "print_standard_errors",
           "units_label"]

# Parameters printed by `fit`; a larger model's others are in its file.
MAX_SHOWN = 24


def print_parameters(comp, se: dict | None) -> None:
    """The fitted parameters as an aligned table (name, value, standard error, relative), as
    lmfit's fit report: n/a where the data do not determine one, 'fixed' where the fit holds
    it (a gauge)."""
    from ..compensation import named_floats
    from ..studies import text_table

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
    print(text_table(("  parameter", "value", "std error", "relative"), rows[:MAX_SHOWN]))
    if len(rows) > MAX_SHOWN:  # a Preisach grid has 191: the rest is in the model file
        print(f"  ... {len(rows) - MAX_SHOWN} more parameter(s): see the model file")


def print_standard_errors(se: dict | None) -> None:
    """One line on the standard errors: the largest relative one, those the data do not
    determine, those the fit holds fixed; and the caveat of a robust or weighted cost."""
    if not se:
        return
    rel = [r for r in se["relative"] if r is not None]
    fixed = se.get("fixed", [])  # held fixed by the fit (a gauge): no SE, not undetermined
    n_blind = sum(r is None for r in se["standard_errors"]) - len(fixed)
    worst = f"largest relative SE {max(rel):.3g}" if rel else "no finite SE"
    print(f"  standard errors (Gauss-Newton, finite-difference Jacobian): {worst}"
          f"{f'; {n_blind} parameter(s) not determined by the data' if n_blind else ''}"
          f"{'; fixed by the fit: ' + ', '.join(fixed) if fixed else ''}")
    if se.get("caveat"):  # a robust or weighted cost, an active constraint
        print(f"    ({se['caveat']})")


def print_band(comp) -> None:
    """The band line of ``fit``: its half-width at the reference rate, or why there is none."""
    note = comp.fit_info.get("band")
    if comp.band is None:
        if note:
            print(f"  {note}")
        return
    unit = (comp.fit_info.get("units") or {}).get("position", "")
    print(f"  prediction band {comp.band.level:.0%}: ±{comp.band.quantile():.4g}"
          f"{' ' + unit if unit else ''} at the training rate, wider when faster or outside the "
          f"training range ({note})")


def units_label(rec) -> str:
    """`` (position [mm], sensor [Ohm])`` when the file gave units, else ""."""
    shown = ", ".join(f"{name} [{unit}]" for name, unit in rec.units)
    return f" ({shown})" if shown else ""
