"""Identification of the Bobbio-Marrucci chain (sec. 2.1.4, eq. 2.5).

For fixed piston thresholds the output ``c_1 u + sum_k c_k F_k + b`` is linear in the spring
compliances and the offset, so the fit is one non-negative least-squares solve (compliances
>= 0, offset free) per candidate threshold set, and the best accepted set wins. The candidate
sets place the play radii ``A_k = a_1 + .. + a_k-1`` of the springs on a grid up to a fraction
``rho`` of the input's half-range, evenly or denser near zero.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import nnls

from ...errors import FitDivergedError
from ...identification import (
    FitResult,
    FitTimer,
    check_fit_data,
    check_weights,
    require_linear_loss,
)
from . import model as bobbio

__all__ = ["SUPPORTED_LOSSES", "candidate_thresholds", "fit_bobbio"]

SUPPORTED_LOSSES = ("linear",)
"""Costs :func:`fit_bobbio` minimises: the (weighted) SSE only (non-negative least squares)."""

_RHO = (0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5)
_SPACING = (1.0, 2.0)  # radius of spring k+1 grows like (k / (N - 1)) ** power


def candidate_thresholds(structure: bobbio.BobbioStructure, u: np.ndarray) -> list[np.ndarray]:
    """Threshold sets ``a`` (shape (N - 1,)) tried by :func:`fit_bobbio`.

    Parameters
    ----------
    structure : bobbio.BobbioStructure
        The chain's structure (``N`` springs).
    u : numpy.ndarray, shape (n,)
        Applied force; its range scales the thresholds.

    Returns
    -------
    list of numpy.ndarray
        Threshold sets, each of shape (N - 1,).
    """
    m = structure.n_springs - 1
    if m == 0:
        return [np.empty(0)]
    half_range = max(0.5 * float(np.ptp(u)), 1e-12)
    grid = np.arange(1, m + 1) / m
    return [np.diff(rho * half_range * grid ** power, prepend=0.0)
            for rho in _RHO for power in _SPACING]


def _solve(u: np.ndarray, y: np.ndarray, structure: bobbio.BobbioStructure,
           a: np.ndarray, weights: np.ndarray | None
           ) -> tuple[bobbio.BobbioParams | None, float, float]:
    """Best compliances >= 0 and offset for thresholds ``a``, its (weighted) SSE and plain
    SSE."""
    probe = bobbio.BobbioParams(compliance=np.zeros(structure.n_springs), friction=a)
    f, _ = bobbio.forces(structure, probe, u)
    design = np.column_stack([u, f])
    # the offset is free: eliminate it by (weighted) centring, then solve the non-negative
    # part, its rows scaled by sqrt(w)
    if weights is None:
        mean_x, mean_y = design.mean(axis=0), y.mean()
        c, _ = nnls(design - mean_x, y - mean_y)
    else:
        mean_x, mean_y = weights @ design / weights.sum(), weights @ y / weights.sum()
        root = np.sqrt(weights)
        c, _ = nnls((design - mean_x) * root[:, None], (y - mean_y) * root)
    offset = mean_y - mean_x @ c
    if max(float(np.max(c)), abs(offset)) > bobbio.MAX_VALUE:  # outside the bounded domain
        return None, np.inf, np.inf
    params = bobbio.BobbioParams(compliance=c, friction=a, offset=offset)
    resid = design @ c + params.offset - y
    sse = float(resid @ resid)
    return params, sse if weights is None else float(weights @ (resid * resid)), sse


def fit_bobbio(u: np.ndarray, y: np.ndarray, structure: bobbio.BobbioStructure, *,
               thresholds: list[np.ndarray] | None = None,
               accept: Callable[[bobbio.BobbioParams], bool] | None = None,
               accept_reason: str = "rejected by the acceptance test", loss: str = "linear",
               f_scale: float = 1.0, weights: np.ndarray | None = None) -> FitResult:
    """Fit a Bobbio-Marrucci chain mapping applied force ``u`` to deformation ``y``.

    Parameters
    ----------
    u, y : array, shape (n,)
        Centred, normalised data (eq. 5.10).
    structure : bobbio.BobbioStructure
        The chain's structure (``N`` springs).
    thresholds : list of arrays, optional
        Candidate threshold sets; default :func:`candidate_thresholds` (14 sets).
    accept, accept_reason
        Candidates with ``accept(params)`` false are skipped, cheapest first.
    loss, f_scale : str, float
        Only ``"linear"`` (the SSE): a robust loss is refused with InputError.
    weights : array, shape (n,), optional
        Per-sample weights (finite, >= 0, not all 0): the offset is eliminated by weighted
        means and the rows are scaled by ``sqrt(w)``; candidates are ranked by the weighted
        SSE.

    Returns
    -------
    FitResult
        The best candidate's parameters, plain SSE (``cost``) and minimised cost
        (``objective``).

    Raises
    ------
    ValueError
        If there are no more samples than parameters (``2 N``).
    FitDivergedError
        If every candidate is vetoed or leaves the parameter domain (``MAX_VALUE``).
    InputError
        If `loss` is a robust loss.
    """
    timer = FitTimer()
    require_linear_loss(loss, f_scale, "bobbio", "non-negative least squares")
    u, y = check_fit_data(u, y)
    weights = None if weights is None else check_weights(weights, y.size)
    if u.size <= structure.n_params:
        raise ValueError(f"a Bobbio-Marrucci fit with {structure.n_springs} springs needs more "
                         f"samples than its {structure.n_params} parameters, got {u.size}")
    sets = candidate_thresholds(structure, u) if thresholds is None else thresholds
    fits = sorted((_solve(u, y, structure, np.asarray(a, dtype=float), weights)
                   for a in sets), key=lambda fit: fit[1])
    for n_rejected, (params, objective, cost) in enumerate(fits):
        if params is None:  # only out-of-domain candidates are left
            break
        if accept is None or accept(params):
            return FitResult(structure=structure, params=params, cost=cost,
                             n_evaluations=len(sets), seconds=timer.seconds(),
                             converged=True, message=f"best of {len(sets)} threshold sets "
                             f"({n_rejected} better ones rejected), non-negative least "
                             f"squares per set", n_starts=len(sets), objective=objective,
                             weighted=weights is not None)
    reason = accept_reason if fits[0][0] is not None else (
        f"their compliances or offset exceed {bobbio.MAX_VALUE:g}")
    raise FitDivergedError(f"the fit failed: all {len(fits)} candidate fits were rejected "
                           f"({reason})")

