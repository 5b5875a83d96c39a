"""Any family's parameters as one flat vector, through the family-neutral ``to_dict``.

Generic code (joint fits over several recordings, standard errors) needs ``theta -> params``
without knowing the family; ``params.to_dict()`` / ``type(params).from_dict`` give it. Integer
entries are structural (counts, flags), so they are kept fixed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

__all__ = ["flatten_params", "simulate_segments"]


def _floats(tree: Any) -> list[float]:
    """Float leaves of a nested dict / list tree, depth first (lists may be ragged)."""
    if isinstance(tree, dict):
        return [x for v in tree.values() for x in _floats(v)]
    if isinstance(tree, list | tuple):
        return [x for v in tree for x in _floats(v)]
    return [float(tree)] if isinstance(tree, float) else []


def _replace_floats(tree: Any, values: Iterator[float]) -> Any:
    if isinstance(tree, dict):
        return {k: _replace_floats(v, values) for k, v in tree.items()}
    if isinstance(tree, list | tuple):
        return [_replace_floats(v, values) for v in tree]
    return float(next(values)) if isinstance(tree, float) else tree


def flatten_params(params: Any) -> tuple[np.ndarray, Callable[[np.ndarray], Any]]:
    """``(theta, rebuild)``: the float entries of ``params.to_dict()`` and their inverse."""
    d = params.to_dict()
    theta = np.array(_floats(d), dtype=float)
    cls = type(params)

    def rebuild(vector: np.ndarray) -> Any:
        return cls.from_dict(_replace_floats(d, iter(np.asarray(vector, dtype=float))))

    return theta, rebuild


def simulate_segments(run: Callable[..., tuple[np.ndarray, np.ndarray]], structure: Any,
                      params: Any, inputs: list[np.ndarray]) -> np.ndarray:
    """Concatenated output of ``run`` over several recordings, each from its own rest state."""
    return np.concatenate([run(structure, params, u)[0] for u in inputs])
