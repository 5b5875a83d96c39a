"""Parameter standard errors without the ``n x p`` Jacobian: its ``R`` factor, chunk by chunk.

:func:`~._diagnostics.standard_errors` differentiates the whole residual and takes the SVD of
the dense Jacobian, ``n_samples x n_params`` floats (+3.7 times the data in ``hystkit fit``).
Here the base and the ``p`` perturbed parameter sets run over one chunk at a time, each carrying
its own state into the next chunk (a split run equals the whole run for every family), and the
chunk's Jacobian rows are folded into the triangular factor of a running QR decomposition
(``R <- qr([R; J_chunk])``, TSQR). ``R`` has the Jacobian's singular values and right singular
vectors, so the standard errors, the undetermined parameters and the condition number are the
dense route's, with memory ``O(chunk x n_params)``. Forward differences (not a family's exact
sensitivities) keep the numbers those of the dense route. Parameters the family's fit holds
fixed (:meth:`hystkit.models.Family.fixed_params`, a gauge) are not differentiated: they are
reported as fixed, not as undetermined.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

from .._blas import one_blas_thread
from ..models import Family
from ._diagnostics import (
    error_steps,
    errors_from_factor,
    fixed_mask,
    parameter_names,
    step_within_domain,
)
from ._param_vector import flatten_params

__all__ = ["chunked_standard_errors"]

# Jacobian entries per chunk (rows x parameters): 2**18 floats, 2 MB, whatever the model size.
_CHUNK_ENTRIES = 1 << 18


def chunked_standard_errors(family: Family, structure: Any, params: Any,
                            inputs: Sequence[np.ndarray], targets: Sequence[np.ndarray], *,
                            chunk: int | None = None) -> dict:
    """Standard errors of the float parameters of ``family.simulate`` fitted to ``targets``.

    Parameters
    ----------
    family, structure, params
        The fitted model; ``params``' float entries (``to_dict`` order) are differentiated,
        except those the family's fit holds fixed (``family.fixed_params``).
    inputs, targets : sequences of arrays
        Input and target per recording; each recording runs from the family's rest state.
    chunk : int, optional
        Samples per chunk (default: about 2**18 / n_params).

    Returns
    -------
    dict
        As :func:`~._diagnostics.standard_errors`.
    """
    theta, rebuild = flatten_params(params)
    free = ~fixed_mask(family, structure, params)
    steps = error_steps(theta)[free]
    shifted = [params]
    for j, e in enumerate(np.eye(theta.size)[free]):
        moved, steps[j] = step_within_domain(rebuild, theta, e, steps[j])
        shifted.append(params if moved is None else moved)
    rows = chunk or max(256, _CHUNK_ENTRIES // max(steps.size, 1))
    r_factor, sse, n = np.zeros((0, steps.size)), 0.0, 0
    # one BLAS thread for the QR folds and the SVD (tall, narrow or small: a QR of 8200 x 192
    # took 164-179 ms of CPU on OpenBLAS's two threads against 40-43 ms on one, under load)
    with one_blas_thread():
        for u, target in zip(inputs, targets, strict=True):
            for r0, jac in _jacobian_chunks(family, structure, shifted, steps, u, target, rows):
                sse += float(r0 @ r0)
                n += r0.size
                r_factor = np.linalg.qr(np.vstack([r_factor, jac]), mode="r")
        return errors_from_factor(theta, r_factor, sse, n, free, parameter_names(params))


def _jacobian_chunks(family: Family, structure: Any, shifted: list, steps: np.ndarray,
                     u: np.ndarray, target: np.ndarray, rows: int
                     ) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """``(residual, forward-difference Jacobian)`` of one recording, ``rows`` samples at a time;
    the same arithmetic as the dense route, so each chunk's rows are its rows."""
    states: list[Any] = [None] * len(shifted)
    for start in range(0, u.size, rows):
        u_chunk, t_chunk = u[start:start + rows], target[start:start + rows]
        residuals = []
        for i, params in enumerate(shifted):
            y, states[i] = family.simulate(structure, params, u_chunk, states[i])
            residuals.append(y - t_chunk)
        r0 = residuals[0]
        jac = np.empty((r0.size, steps.size))
        for j, h in enumerate(steps):
            jac[:, j] = (residuals[j + 1] - r0) / h
        yield r0, jac
