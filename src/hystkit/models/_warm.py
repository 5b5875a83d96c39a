"""Loading every model kernel: what a Dask worker runs at its start (the ``worker_setup`` that
the commands hand to `hystkit.parallel.open_executor`).

The default forked workers do not use it: each loads the kernels its pieces use when it first
runs them (`hystkit.parallel._forked`), which on 2 cores costs less wall time than loading all
of them in the parent before the fork.
"""

from __future__ import annotations

import numpy as np

from ._registry import FAMILIES

__all__ = ["warm_kernels"]


def warm_kernels() -> None:
    """Import the model families, fit each one to a short hysteretic signal and invert it:
    this loads their simulation, fit and inverse kernels from numba's on-disk cache
    (``cache=True``). The signal is a play operator's (every family fits it; a family's own
    random parameters left Bouc-Wen unfitted, its fit kernels unloaded) and short: ~1.05 s of
    CPU on the 2-core machine, of which ~0.6 s runs the fits (2026-11-24). It is what a Dask
    worker runs at its start (``open_executor(..., worker_setup=warm_kernels)``).
    """
    u = 0.8 * np.sin(np.linspace(0, 6 * np.pi, 150)) * np.linspace(1.0, 0.5, 150)
    y = 0.6 * u + 0.4 * _play(u, 0.15)
    for family in FAMILIES.values():
        # Only a head start: a family that cannot run here fails in its own piece, where the
        # command reports it, not in every worker's start-up.
        try:
            structure = family.make_structure(1 / 40, family.default_size)
            params = family.fit(u, y, structure).params
            if family.invert is not None:  # compare and select score the inverse too
                family.invert(structure, params, y)
        except Exception:  # noqa: BLE001, S112
            continue


def _play(u: np.ndarray, radius: float) -> np.ndarray:
    """A play (backlash) operator of half-width `radius` from 0: a simple hysteretic loop."""
    y, x = np.empty_like(u), 0.0
    for i, v in enumerate(u):
        x = min(max(x, v - radius), v + radius)
        y[i] = x
    return y
