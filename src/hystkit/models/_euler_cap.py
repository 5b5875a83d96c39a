"""A capped-Euler structure moved to another sample time (the chua and ladder families' ``at``)."""

from __future__ import annotations

import dataclasses
from typing import Any

__all__ = ["at_same_limit"]


def at_same_limit(structure: Any, dt: float) -> Any:
    """`structure` at sample time `dt`, its ``slope_cap`` scaled with ``dt`` so that the
    absolute limit ``slope_cap / dt`` (1/s) stays the one the model was fitted with.

    The relative cap saturates at ``max(slope_cap, 1)``: at a coarser step that would need
    more, the Euler step stays monotone and the absolute limit falls instead.

    Parameters
    ----------
    structure : dataclass
        A frozen structure with ``dt`` and ``slope_cap`` fields.
    dt : float
        The new sample time [s].

    Returns
    -------
    dataclass
        A copy of `structure` with the new ``dt`` and ``slope_cap``.
    """
    dt = float(dt)
    cap = min(structure.slope_cap * dt / structure.dt, max(structure.slope_cap, 1.0))
    return dataclasses.replace(structure, dt=dt, slope_cap=cap)
