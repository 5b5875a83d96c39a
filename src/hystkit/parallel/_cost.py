"""A-priori cost of one fit, to submit the costliest pieces of a parallel map first.

Only the order matters: a long fit started last runs alone at the end while the other workers
idle (the critical path), so the map sends the costliest pieces first. The estimate is a
family's measured fit time on 8000 samples at its default size (``compare`` and
``generalize`` pieces, one core, 2026-11-24), linear in the samples and quadratic in the size
(an mPL of 3 cells costs ~9x one of 1 cell in ``select``). A family not in the table gets the
median.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["cost_order", "fit_cost"]

# family: (seconds of fit and scoring on 8000 samples, the size they were measured at)
MEASURED = {
    "bobbio": (0.05, 10), "boucwen": (1.2, 2), "chua": (0.6, 1), "gpreisach": (0.5, 16),
    "ladder": (0.5, 2), "mpl": (0.07, 1), "mpl-g": (0.1, 1), "mpl-poly": (0.25, 1),
    "pi": (0.06, 10), "pl": (0.4, 1), "preisach": (0.25, 20),
}
_MEDIAN = sorted(s for s, _ in MEASURED.values())[len(MEASURED) // 2]


def fit_cost(model: str, size: int | None, n_samples: int) -> float:
    """Estimated seconds of one fit of `model` at `size` (None: its default) on `n_samples`.

    A rough a-priori figure for ordering work, never a promise of run time.

    Parameters
    ----------
    model : str
        Model family name (``"mpl"``, ``"boucwen"``, ...); one not measured gets the median.
    size : int or None
        Model size; None: the family's default (the size it was measured at).
    n_samples : int
        Samples of the recording to fit.

    Returns
    -------
    float
        Estimated seconds on one core: linear in `n_samples`, quadratic in `size`.
    """
    seconds, measured_size = MEASURED.get(model, (_MEDIAN, None))
    ratio = 1.0 if size is None or measured_size is None else size / measured_size
    return seconds * ratio * ratio * n_samples / 8000


def cost_order(items: Sequence[Any], cost: Callable[[Any], float] | None) -> list[int]:
    """Indices of `items`, the costliest first by `cost`; ties, and all without `cost`, in
    the order of `items`."""
    if cost is None:
        return list(range(len(items)))
    return sorted(range(len(items)), key=lambda i: (-cost(items[i]), i))
