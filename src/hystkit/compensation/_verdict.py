"""One verdict per model: is this compensator worth using on the data it is judged on?

The same rules serve every command that judges a model (``fit``, ``select``, ``evaluate``,
``compare``, ``generalize``, ``batch``, ``report``), so that they cannot disagree:

- ``worse_than_line``: the model loses to its own straight line on the same data.
- ``no_signal``: it does not, but its estimate explains less than ``MIN_EXPLAINED`` of the
  position's variance (its error is at least ~95 % of the position's own spread): the sensor,
  as modelled, carries nothing a compensator can use (e.g. a noise-only sensor column).
- ``extrapolated``: it does neither, but more than ``MAX_OUTSIDE`` of the sensor samples lie
  far outside the range the model was trained on (beyond it by more than ``FAR_MARGIN`` of
  its width): whatever it scores there, it works by luck, not by what it learnt (judged only
  where that share is given, e.g. by ``evaluate``). Samples just outside the range are
  warned about per sample, not judged here.
- ``undetermined``: R² is undefined there (a position that never moves): nothing to judge by.
- ``ok``: none of these.

A fit adds its own checks before these (:func:`~._diagnostics.fit_status`: a collapsed
estimate, parameters on the search box, a solver that did not converge).
"""

from __future__ import annotations

__all__ = ["FAR_MARGIN", "MAX_OUTSIDE", "MIN_EXPLAINED", "USE_STATUSES", "use_verdict",
           "verdict"]

# Below this R² the estimate is no better than reporting a constant in any useful sense.
MIN_EXPLAINED = 0.1
# The statuses of this module: ``ok`` may be used, ``undetermined`` cannot be judged (no R²),
# the others must not be used.
USE_STATUSES = ("no_signal", "worse_than_line", "extrapolated", "undetermined", "ok")
# More than this share of sensor samples far outside the training range (beyond it by more
# than FAR_MARGIN of its width on either side) is use beyond the model.
MAX_OUTSIDE = 0.1
FAR_MARGIN = 0.5


def verdict(r2_model: float | None, r2_line: float | None, where: str,
            outside: float | None = None) -> tuple[str, str]:
    """``(status, message)`` of a model scored on some data against its straight line.

    Parameters
    ----------
    r2_model, r2_line : float or None
        R² of the model's and of the straight line's estimate on the same samples; None where
        undefined (a position that never moves, an overflow).
    where : str
        What the scores are of, for the message: ``"training"``, ``"held-out (left-out
        recording)"``, a file name.
    outside : float, optional
        Share of the scored sensor samples far outside the model's training range (beyond it
        by more than ``FAR_MARGIN`` of its width); None: not judged.

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
    if outside is not None and outside > MAX_OUTSIDE:
        return "extrapolated", (f"{outside:.0%} of the sensor samples lie far outside the "
                                f"range the model was trained on (by more than "
                                f"{FAR_MARGIN:.0%} of its width; {where} R² {r2_model:.4f}): "
                                f"retrain on data that covers this range")
    return "ok", f"{where} R² {r2_model:.4f} (straight line {line})"


def use_verdict(compensator, recording, scores: dict, where: str) -> tuple[str, str]:
    """:func:`verdict` of a compensator on a recording from :func:`~._evaluate.evaluate`'s
    deployable scores, with the share of its sensor samples far outside the training range.

    Parameters
    ----------
    compensator : Compensator
        The fitted compensator.
    recording : Recording
        The scored recording.
    scores : dict
        ``evaluate(compensator, recording)``.
    where : str
        What the scores are of, for the message.

    Returns
    -------
    tuple of str
        As :func:`verdict`.
    """
    far = compensator.sensor_outside(recording, margin=FAR_MARGIN)
    return verdict(scores["r2"], scores["linear_r2"], where,
                   None if far is None else float(far.mean()))
