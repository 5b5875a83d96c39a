"""Any family's parameters as one flat vector, through the family-neutral ``to_dict``.

Generic code (joint fits over several recordings, standard errors) needs ``theta -> params``
without knowing the family; ``params.to_dict()`` / ``type(params).from_dict`` give it. Integer
entries are structural (counts, flags), so they are kept fixed.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["flatten_params", "simulate_segments"]


def flatten_params(params: Any) -> tuple[np.ndarray, Callable[[np.ndarray], Any]]:
    """``(theta, rebuild)``: the float entries of ``params.to_dict()`` and their inverse."""
    d = params.to_dict()
    keys = [k for k, v in d.items()
            if np.asarray(v).dtype.kind == "f" and np.asarray(v).size > 0]
    shapes = [np.shape(d[k]) for k in keys]
    sizes = [int(np.prod(s)) for s in shapes]
    theta = np.concatenate([np.ravel(np.asarray(d[k], dtype=float)) for k in keys]) \
        if keys else np.zeros(0)
    cls = type(params)

    def rebuild(vector: np.ndarray) -> Any:
        out, start = dict(d), 0
        for key, shape, size in zip(keys, shapes, sizes, strict=True):
            values = np.asarray(vector[start:start + size], dtype=float).reshape(shape)
            out[key] = values.tolist() if shape else float(values)
            start += size
        return cls.from_dict(out)

    return theta, rebuild


def simulate_segments(run: Callable[..., tuple[np.ndarray, np.ndarray]], structure: Any,
                      params: Any, inputs: list[np.ndarray]) -> np.ndarray:
    """Concatenated output of ``run`` over several recordings, each from its own rest state."""
    return np.concatenate([run(structure, params, u)[0] for u in inputs])
