"""Loading the model kernels once, in the process that forks the workers."""

from __future__ import annotations

import numpy as np

__all__ = ["warm_kernels", "warmed"]

# Whether this process (or the one it was forked from) has run `warm_kernels`.
_warmed = False


def warm_kernels() -> None:
    """Import the model families, fit each one to a short hysteretic signal and invert it:
    this loads their simulation, fit and inverse kernels from numba's on-disk cache
    (``cache=True``) once, here, instead of in every worker (measured: without the fits'
    kernels, two forked workers each loaded them again and a 4 s ``compare`` map took as long
    on 2 workers as on 1). The signal is a play operator's (every family fits it; a family's
    own random parameters left Bouc-Wen unfitted, its fit kernels unloaded) and short:
    loading is what counts here (~1.5 s of CPU, of which ~0.7 s runs the fits)."""
    global _warmed
    from ..models import FAMILIES

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
    _warmed = True


def warmed() -> bool:
    """Whether this process, or the one it was forked from, has run `warm_kernels`."""
    return _warmed


def _play(u: np.ndarray, radius: float) -> np.ndarray:
    """A play (backlash) operator of half-width `radius` from 0: a simple hysteretic loop."""
    y, x = np.empty_like(u), 0.0
    for i, v in enumerate(u):
        x = min(max(x, v - radius), v + radius)
        y[i] = x
    return y
