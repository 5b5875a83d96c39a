"""The Prandtl-Ishlinskii structure of a fit (:func:`make_structure`), the fit's coordinates
(:func:`params_from_theta`, which keep Kuhnen's invertibility condition) and the documented
domain drawn in them (:func:`random_params`); light (no optimiser loaded), so the family object
reads it at import.
"""

from __future__ import annotations

import numpy as np

from .._docs import docfiller
from . import model as pi

fill_doc = docfiller()

__all__ = ["MIN_SLOPE", "make_structure", "params_from_theta", "random_params"]


MIN_SLOPE = 0.01  # smallest loading-curve / S^-1 slope, in normalised units (slope 1 = linear)


def params_from_theta(structure: pi.PiStructure, theta: np.ndarray, d_inv: np.ndarray,
               polarity: float) -> pi.PiParams:
    """Optimiser unknowns (slopes, split creep weights) -> weights of the forward model."""
    n, n_k, m = structure.n_play, structure.n_creep, structure.n_deadzone
    w_up, w_down = theta[n:n + n_k], theta[n + n_k:n + 2 * n_k]
    slopes = theta[:n] + w_down.sum()
    s_up, s_down = theta[n + 2 * n_k + 1:n + 2 * n_k + 1 + m], theta[n + 2 * n_k + 1 + m:]
    ws_inv = np.concatenate([np.diff(np.r_[1.0, s_down])[::-1], [1.0],
                             np.diff(np.r_[1.0, s_up])])
    d_s, w_s = pi.inverse_superposition(d_inv, ws_inv)
    return pi.PiParams(w_h=polarity * np.diff(slopes, prepend=0.0), w_s=w_s, d_s=d_s,
                       w_k=polarity * (w_up - w_down), b=theta[n + 2 * n_k])


def make_structure(dt: float, size: int, *, n_deadzone: int = 2, n_creep: int = 4,
                   r_max: float = 1.0, tau_min: float = 0.1) -> pi.PiStructure:
    """``size`` evenly spread play thresholds and creep time constants a decade apart.

    ``r_i = i r_max / size`` (i = 0 .. size - 1): Kuhnen's equidistant thresholds over the input
    amplitude (``r_max = 1`` for data normalised to max |.| = 1, eq. 5.10). ``n_deadzone``
    dead zones per side. ``a_j = 1 / (tau_min 10^j)`` (j = 0 .. n_creep - 1): by default time
    constants 0.1, 1, 10 and 100 s, from 4 samples at 40 Hz to half a recording.

    Parameters
    ----------
    dt : float
        Sample time [s].
    size : int
        Play operators.
    n_deadzone : int, default 2
        Dead zones per side.
    n_creep : int, default 4
        Creep operators.
    r_max : float, default 1.0
        Largest input amplitude the thresholds spread over.
    tau_min : float, default 0.1
        Shortest creep time constant [s].

    Returns
    -------
    pi.PiStructure
        The structure.

    Raises
    ------
    ValueError
        A size that is not an integer in ``[1, MAX_PLAYS]``.
    """
    # the caps first, before arange allocates anything (a size of 1e12 or inf)
    if not (isinstance(size, int | float) and 1 <= size <= pi.MAX_PLAYS) or int(size) != size:
        raise ValueError(f"size (play operators) must be an integer in [1, {pi.MAX_PLAYS}], "
                         f"got {size!r}")
    if not (isinstance(n_creep, int | float) and 0 <= n_creep <= pi.MAX_CREEP) \
            or int(n_creep) != n_creep:
        raise ValueError(f"n_creep must be an integer in [0, {pi.MAX_CREEP}], got {n_creep!r}")
    if not (r_max > 0 and tau_min > 0):
        raise ValueError(f"r_max and tau_min must be positive, got {r_max!r}, {tau_min!r}")
    return pi.PiStructure(play_thresholds=tuple(r_max * np.arange(size) / size),
                          n_deadzone=n_deadzone,
                          creep_rates=tuple(1.0 / (tau_min * 10.0 ** np.arange(n_creep))), dt=dt)


@fill_doc
def random_params(structure: pi.PiStructure, rng: np.random.Generator) -> pi.PiParams:
    """Parameters drawn in the fit's coordinates (the family's documented domain, see
    ``PiFamily.random_params``).

    Parameters
    ----------
    structure : pi.PiStructure
        The model's structure.
    %(rng)s

    Returns
    -------
    pi.PiParams
        The drawn parameters.
    """
    n, n_k, m = structure.n_play, structure.n_creep, structure.n_deadzone
    log_slope = np.log(MIN_SLOPE), -np.log(MIN_SLOPE)
    theta = np.concatenate([np.exp(rng.uniform(*log_slope, n)), rng.uniform(0.0, 1.0, 2 * n_k),
                            [rng.uniform(-1.0, 1.0)], np.exp(rng.uniform(*log_slope, 2 * m))])
    d_inv = np.concatenate([-np.arange(m, 0, -1), [0.0], np.arange(1, m + 1)]) / (m + 1)
    return params_from_theta(structure, theta, d_inv, float(rng.choice([-1.0, 1.0])))
