"""The runaway guard: estimates a compensator never returns (a model's output far beyond its
training data, or not finite), shared by :meth:`Compensator.estimate`, the live stream and
the exported C / MATLAB code (which take ``MAX_NORMALISED`` from here).
"""

from __future__ import annotations

import numpy as np

from ..io import MAX_MAGNITUDE

__all__ = ["MAX_NORMALISED", "runaway_kind", "runaway_samples"]

# An estimate beyond this many times the (normalised, max |.| = 1) training positions is refused.
MAX_NORMALISED = 1e6


def runaway_samples(p: np.ndarray, estimate: np.ndarray,
                    bounds: tuple[float, float] | None = None) -> np.ndarray:
    """Indices of the samples the runaway guard refuses: the model's normalised output beyond
    ``MAX_NORMALISED`` (normalised training data have |p| <= 1), or, after de-normalisation,
    an estimate that is not finite, beyond ``MAX_MAGNITUDE`` mm (no recording could hold it)
    or outside `bounds` (:meth:`Compensator.runaway_bounds`: a position scale that does not
    fit the training positions).

    Parameters
    ----------
    p : numpy.ndarray, shape (n,)
        The model's output in normalised units.
    estimate : numpy.ndarray, shape (n,)
        The same de-normalised [mm].
    bounds : tuple of float, optional
        ``(low, high)`` [mm] the estimates must lie within; None: no such bound.

    Returns
    -------
    numpy.ndarray of int
        The refused samples' indices, in order (empty if none).
    """
    estimate = np.asarray(estimate, dtype=float)
    # NaN fails every comparison: written so that it is refused too
    ok = (np.abs(np.asarray(p, dtype=float)) <= MAX_NORMALISED) \
        & (np.abs(estimate) <= MAX_MAGNITUDE)
    if bounds is not None:
        ok &= (estimate >= bounds[0]) & (estimate <= bounds[1])
    return np.flatnonzero(~ok)


def runaway_kind(value: float) -> str:
    """What is wrong with a refused estimate [mm] (:func:`runaway_samples`), for messages.

    Parameters
    ----------
    value : float
        The first refused estimate [mm].

    Returns
    -------
    str
        ``"not finite"``, or its value and the bound it passes.
    """
    if not np.isfinite(value):
        return "not finite"
    if abs(value) > MAX_MAGNITUDE:
        return f"{value:.3g} mm, beyond the largest magnitude {MAX_MAGNITUDE:g} of any recording"
    return f"{value:.3g} mm, beyond {MAX_NORMALISED:g} times the training range"
