"""TRANSITIONAL: the first registry's family record, until every family has its folder.

A family is a module ``family_<name>.py`` in this folder exporting ``FAMILY``, a
:class:`ModelFamily`; the registry finds them, so adding a model edits no shared file.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._result import FitResult

__all__ = ["ModelFamily"]


@dataclass(frozen=True)
class ModelFamily:
    """Everything generic code needs to know about one hysteresis model family.

    Attributes
    ----------
    name : str
        CLI name (``hystkit fit --model NAME``).
    title : str
        Human name with the reference document's section.
    structure_type, params_type : type
        Frozen dataclasses; ``structure_type(**d)`` rebuilds a structure from its ``asdict``,
        ``params_type.from_dict`` / ``params.to_dict()`` round-trip the parameters (JSON).
    make_structure : callable
        ``(dt [s], size, **options) -> structure``; ``size`` is the family's size knob (cells,
        operators, grid levels...), described by ``size_help``.
    simulate : callable
        ``(structure, params, u, x0=None) -> (y, x_end)``, pure, explicit state.
    fit : callable
        ``(u, y, structure, accept=None, accept_reason=...) -> FitResult`` on centred,
        normalised data.
    invert : callable or None
        ``(structure, params, y, x0=None) -> (u_hat, x_end)``; None when the family has no
        inverse, with the reason in ``no_inverse_reason``.
    """

    name: str
    title: str
    structure_type: type
    params_type: type
    make_structure: Callable[..., Any]
    simulate: Callable[..., tuple[np.ndarray, np.ndarray]]
    fit: Callable[..., FitResult]
    invert: Callable[..., tuple[np.ndarray, np.ndarray]] | None = None
    no_inverse_reason: str = ""
    size_help: str = "model size"
    default_size: int = 1
