"""One verdict per model: is this compensator worth using on the data it is judged on?

The same rules serve every command that judges a model (``fit``, ``select``, ``evaluate``,
``compare``, ``generalize``, ``batch``, ``report``), so that they cannot disagree:

- ``worse_than_line``: the model loses to its own straight line on the same data.
- ``no_signal``: it does not, but its estimate explains less than ``MIN_EXPLAINED`` of the
  position's variance (its error is at least ~95 % of the position's own spread): the sensor,
  as modelled, carries nothing a compensator can use (e.g. a noise-only sensor column).
- ``undetermined``: R² is undefined there (a position that never moves): nothing to judge by.
- ``ok``: none of these.

A fit adds its own checks before these (:func:`~._diagnostics.fit_status`: a collapsed
estimate, parameters on the search box, a solver that did not converge).
"""

from __future__ import annotations

__all__ = ["MIN_EXPLAINED", "USE_STATUSES", "verdict"]

# Below this R² the estimate is no better than reporting a constant in any useful sense.
MIN_EXPLAINED = 0.1
# The statuses of this module: ``ok`` may be used, ``undetermined`` cannot be judged (no R²),
# the others must not be used.
USE_STATUSES = ("no_signal", "worse_than_line", "undetermined", "ok")


def verdict(r2_model: float | None, r2_line: float | None, where: str) -> tuple[str, str]:
    """``(status, message)`` of a model scored on some data against its straight line.

    Parameters
    ----------
    r2_model, r2_line : float or None
        R² of the model's and of the straight line's estimate on the same samples; None where
        undefined (a position that never moves, an overflow).
    where : str
        What the scores are of, for the message: ``"training"``, ``"held-out (left-out
        recording)"``, a file name.

    Returns
    -------
    tuple of str
        A status of ``USE_STATUSES`` and one line saying why.
    """
    if r2_model is None:
        return "undetermined", (f"{where} R² is undefined (the position does not move, or an "
                                f"overflow): nothing to judge the model by")
    line = "n/a" if r2_line is None else f"{r2_line:.4f}"
    if r2_line is not None and r2_model < r2_line:
        return "worse_than_line", (f"{where} R² {r2_model:.4f} is below the straight line's "
                                   f"{r2_line:.4f}")
    if r2_model < MIN_EXPLAINED:
        return "no_signal", (f"{where} R² {r2_model:.4f} (straight line {line}): the estimate "
                             f"explains less than {MIN_EXPLAINED:.0%} of the position's "
                             f"variance, no better than a constant")
    return "ok", f"{where} R² {r2_model:.4f} (straight line {line})"
