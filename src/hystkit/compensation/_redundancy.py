"""Redundant cells: does a smaller model describe the training data as well as the fitted one?

A fit with more cells than the data resolve still converges (the solver reports success on a
flat valley), and its R² is excellent: only the parameters are not identified. The symptom
seen is two cells whose weights nearly cancel (-14.6 and +12.8 on a clean sine, where one
weight of -1.8 does the same) or a cell of weight ~0. Cancelling weights alone prove nothing,
though: on the virtual sensor's noise run a 3-cell fit with weights -2.76 and +2.57 has 30 %
less SSE than the best 2-cell fit, the difference of two unlike cells being a shape of its own.

So the check measures: the family offers models one size smaller made from the fitted one
without refitting (:meth:`hystkit.models.Family.reductions`: a cell dropped, two merged), each
is run on the training data, and the best is kept when BIC prefers it to the fitted model,
``n ln(SSE_small / SSE) <= (k - k_small) ln n``. Not refitting makes this conservative: a
refit of the smaller model can only lower its SSE. The step is repeated on the smaller model
while BIC still prefers it. The result is a note for ``fit_info``, not a failed guard: the
fitted model predicts as well as the smaller one, it only carries parameters the data do not
determine (their standard errors say so).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import HystkitError
from ..models import Family, Reduction
from ._diagnostics import fixed_mask
from ._param_vector import flatten_params, simulate_segments

__all__ = ["ROUND_OFF", "redundancy_notes"]

# A residual RMS below this share of the target's RMS is round-off (a model fitted to its own
# noise-free output reaches 1e-14): SSEs below it are the same, whatever their ratio.
ROUND_OFF = 1e-9


def redundancy_notes(family: Family, structure: Any, params: Any,
                     inputs: Sequence[np.ndarray], targets: Sequence[np.ndarray],
                     sse: float) -> list[str]:
    """One note when a smaller model, made from the fitted one, describes the data as well.

    Parameters
    ----------
    family, structure, params
        The fitted model (forward: ``family.simulate`` maps ``inputs`` to ``targets``).
    inputs, targets : sequences of arrays
        Normalised input and target per training recording, each run from rest.
    sse : float
        The fitted model's SSE on them.

    Returns
    -------
    list of str
        Empty, or one line: what can go, the smaller size, the SSE change and the refit
        (``'cells 2 and 3 cancel (weights -14.6, +12.8): these data are described as well by
        2 cells ...; refit with --cells 2'``).
    """
    n = int(sum(np.size(t) for t in targets))
    k_full = _n_fitted(family, structure, params)
    if n < 2 or not np.isfinite(sse) or k_full is None:
        return []
    floor = float(sum(np.sum(np.square(t)) for t in targets)) * ROUND_OFF ** 2
    if floor <= 0:
        return []
    sse = max(sse, floor)
    steps: list[tuple[Reduction, float]] = []
    model = (structure, params)
    while best := _best_reduction(family, *model, inputs, targets, floor):
        reduction, sse_small = best
        k_small = _n_fitted(family, reduction.structure, reduction.params)
        if k_small is None or n * np.log(sse_small / sse) > (k_full - k_small) * np.log(n):
            break
        steps.append((reduction, sse_small))
        model = (reduction.structure, reduction.params)
    if not steps:
        return []
    first, (last, sse_small) = steps[0][0], steps[-1]
    more = "" if len(steps) == 1 else f", then {len(steps) - 1} more cell(s)"
    fewer = k_full - _n_fitted(family, last.structure, last.params)
    note = (f"{first.what}{more}: these data are described as well by {last.label} (training "
            f"SSE {100 * (sse_small / sse - 1):+.2g} % without refitting, which BIC prefers for "
            f"{fewer} fewer parameters); refit with --cells {last.size}")
    return [note]


def _best_reduction(family: Family, structure: Any, params: Any,
                    inputs: Sequence[np.ndarray], targets: Sequence[np.ndarray], floor: float
                    ) -> tuple[Reduction, float] | None:
    """The family's smaller model with the least SSE on the data (not below `floor`: among
    models at round-off the family's first, a dropped cell before a merge), or None."""
    target = np.concatenate(targets)
    best = None
    for reduction in family.reductions(structure, params):
        try:
            residual = simulate_segments(family.simulate, reduction.structure,
                                         reduction.params, list(inputs)) - target
        except (HystkitError, ValueError, ArithmeticError):  # a smaller model that diverges
            continue
        sse = max(float(residual @ residual), floor)
        if np.isfinite(sse) and (best is None or sse < best[1]):
            best = (reduction, sse)
    return best


def _n_fitted(family: Family, structure: Any, params: Any) -> int | None:
    """Fitted numbers (float entries the family's fit does not hold fixed)."""
    try:
        fixed = fixed_mask(family, structure, params)
    except ValueError:
        return None
    return int(flatten_params(params)[0].size - np.count_nonzero(fixed))
