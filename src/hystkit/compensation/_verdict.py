"""One verdict per model: is this compensator worth using on the data it is judged on?

The same rules serve every command that judges a model (``fit``, ``select``, ``evaluate``,
``compare``, ``generalize``, ``batch``, ``report``), so that they cannot disagree. The first
that applies gives the status:

- ``undetermined``: R² is undefined there (a position that never moves): nothing to judge by.
- ``worse_than_line``: the model loses to its own straight line on the same data.
- ``no_signal``: it does not, but its estimate explains less than ``MIN_EXPLAINED`` of the
  position's variance (its error is at least ~95 % of the position's own spread): the sensor,
  as modelled, carries nothing a compensator can use (e.g. a noise-only sensor column).
- ``extrapolated``: more than ``MAX_OUTSIDE`` of the sensor samples, or of the estimates, lie
  far outside the range the model was trained on (beyond the training sensor range, or the
  training position range, by more than ``FAR_MARGIN`` of its width): whatever it scores
  there, it works by luck, not by what it learnt. The estimate's range counts as much as the
  sensor's: a sensor inside its training range can still drive the model to positions it never
  produced in training (an MR damper's force saturates while the stroke doubles). Judged only
  where these shares are given (``evaluate`` and those built on it). Samples just outside the
  range are warned about per sample, not judged here.
- ``poor``: none of these, but the estimate explains less than ``MIN_USABLE`` of the position's
  variance (its error is above half of the position's own spread): the sensor carries signal,
  yet this model, on these data, is too far off to compensate with.
- ``ok``: none of these.

``MIN_USABLE`` comes from a labelled corpus of 36 measured and simulated train/test pairs (MR
damper, B(H) loops, micromanipulator, piezo actuator, virtual sensor; its edges are
``tests/compensation/test_verdict_use.py``): compensators that work on a held-out run of the
same device score R² 0.81-1.00 there, the failures that no other rule catches 0.19-0.73 (another
coil current, rate or loop amplitude). 0.75, an error of half the position's spread, lies in
that gap.

A band's coverage is not judged: on the micromanipulator's test run a compensator with R²
0.995 has a 90 % band that covers 26 % of it (the offset moved between runs); the band's
own scores say so, the compensator is still usable.

A fit adds its own checks before these (:func:`~._diagnostics.fit_status`: a collapsed
estimate, parameters on the search box, a solver that did not converge).
"""

from __future__ import annotations

from collections.abc import Sequence

from .._docfill import docfiller

__all__ = ["FAR_MARGIN", "MAX_OUTSIDE", "MIN_EXPLAINED", "MIN_USABLE", "USE_STATUSES",
           "pooled_verdict", "use_verdict", "verdict"]

# What the verdicts of scores take and return (%(where)s, %(as_verdict)s).
VERDICT_ENTRIES = {
    "where": """where : str
    What the scores are of, for the message.""",
    "as_verdict": """Returns
-------
tuple of str
    As :func:`verdict`.""",
}
fill_verdict_doc = docfiller(VERDICT_ENTRIES.__getitem__)

# Below this R² the estimate is no better than reporting a constant in any useful sense.
MIN_EXPLAINED = 0.1
# Below this R² (an error above half of the position's spread) a compensator is not usable:
# in the corpus, working compensators score >= 0.81 held out, the failures no other rule
# catches <= 0.73 (see the module docstring).
MIN_USABLE = 0.75
# The statuses of this module: ``ok`` may be used, ``undetermined`` cannot be judged (no R²),
# the others must not be used.
USE_STATUSES = ("no_signal", "poor", "worse_than_line", "extrapolated", "undetermined", "ok")
# More than this share of sensor samples (or of estimates) far outside the training range
# (beyond it by more than FAR_MARGIN of its width on either side) is use beyond the model.
MAX_OUTSIDE = 0.1
FAR_MARGIN = 0.5


def verdict(r2_model: float | None, r2_line: float | None, where: str,
            outside: float | None = None,
            estimate_outside: float | None = None) -> tuple[str, str]:
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
        Share of the scored sensor samples far outside the model's training sensor range
        (beyond it by more than ``FAR_MARGIN`` of its width); None: not judged.
    estimate_outside : float, optional
        Share of the model's estimates far outside its training position range (the same
        margin); None: not judged.

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
    if estimate_outside is not None and estimate_outside > MAX_OUTSIDE:
        return "extrapolated", (f"{estimate_outside:.0%} of the estimates lie far outside the "
                                f"positions the model was trained on (by more than "
                                f"{FAR_MARGIN:.0%} of their range; {where} R² "
                                f"{r2_model:.4f}): retrain on data that covers these "
                                f"positions")
    if r2_model < MIN_USABLE:
        return "poor", (f"{where} R² {r2_model:.4f} (straight line {line}): its error is "
                        f"{(1 - r2_model) ** 0.5:.0%} of the position's spread; a usable "
                        f"compensator explains at least {MIN_USABLE:.0%} of its variance")
    return "ok", f"{where} R² {r2_model:.4f} (straight line {line})"


@fill_verdict_doc
def use_verdict(scores: dict, where: str) -> tuple[str, str]:
    """:func:`verdict` of a compensator on one recording from :func:`~._evaluate.evaluate`'s
    deployable scores, which carry the counts of sensor samples and estimates far outside
    the training ranges (:func:`pooled_verdict` of one recording).

    Parameters
    ----------
    scores : dict
        ``evaluate(compensator, recording)``.
    %(where)s

    %(as_verdict)s
    """
    return pooled_verdict([scores], where)


@fill_verdict_doc
def pooled_verdict(scores: Sequence[dict], where: str) -> tuple[str, str]:
    """:func:`verdict` of one compensator on several recordings (``batch``'s validation runs):
    the mean deployable R² of each, the far-outside shares pooled over all samples.

    Parameters
    ----------
    scores : sequence of dict
        :func:`~._evaluate.evaluate`'s scores of each recording (``n_sensor_far_outside``,
        ``n_estimate_far_outside``: None where the model file does not know its ranges).
    %(where)s

    %(as_verdict)s
    """
    return verdict(_mean(scores, "r2"), _mean(scores, "linear_r2"), where,
                   _pooled_share(scores, "n_sensor_far_outside"),
                   _pooled_share(scores, "n_estimate_far_outside"))


def _mean(scores: Sequence[dict], key: str) -> float | None:
    """Mean of a score over the recordings; None if any is undefined (or none is given)."""
    values = [s[key] for s in scores]
    return None if not values or any(v is None for v in values) else sum(values) / len(values)


def _pooled_share(scores: Sequence[dict], key: str) -> float | None:
    """Share of all scored samples counted by `key`; None if any recording does not know it."""
    counts = [s.get(key) for s in scores]
    if not counts or any(c is None for c in counts):
        return None
    return sum(counts) / sum(s["n_samples"] for s in scores)
