"""Any family's parameters as one flat vector, through the family-neutral ``to_dict``.

Generic code (joint fits over several recordings, standard errors) needs ``theta -> params``
without knowing the family; ``params.to_dict()`` / ``type(params).from_dict`` give it. Integer
entries are structural (counts, flags), so they are kept fixed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

__all__ = ["flatten_params", "named_floats", "simulate_segments"]


def named_floats(tree: Any, name: str = "") -> list[tuple[str, float]]:
    """``(name, value)`` of the float leaves of a nested dict / list tree, depth first.

    The order of :func:`flatten_params` (lists may be ragged); names as ``w[1]``, ``v_b``,
    ``a[0][2]``, a nested dict's keys joined by dots.

    Parameters
    ----------
    tree : dict, list, tuple or scalar
        E.g. ``params.to_dict()``.
    name : str, default ""
        Name of `tree` itself (a prefix of its leaves' names).

    Returns
    -------
    list of (str, float)
        One entry per float leaf; integers and booleans are structural and left out.
    """
    if isinstance(tree, dict):
        return [leaf for key, value in tree.items()
                for leaf in named_floats(value, f"{name}.{key}" if name else str(key))]
    if isinstance(tree, list | tuple):
        return [leaf for i, value in enumerate(tree)
                for leaf in named_floats(value, f"{name}[{i}]")]
    return [(name, float(tree))] if isinstance(tree, float) else []


def _floats(tree: Any) -> list[float]:
    """Float leaves of a nested dict / list tree, depth first (lists may be ragged)."""
    return [value for _, value in named_floats(tree)]


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
