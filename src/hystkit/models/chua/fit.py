"""Least-squares identification of the Chua-Stromsmoe model (sec. 2.1.3, eq. 2.3).

The SSE (eq. 5.9) is minimised by bounded least squares (``fit_multistart``) over
``ChuaParams.to_vector`` with finite-difference Jacobians: the model has 6 parameters per
element and none enters the output linearly. The normal equations of those differences are
formed chunk by chunk (``ChunkedDifferences``: each perturbed run carries its state from chunk
to chunk), so memory stays ``O(chunk x 6N)`` on long recordings.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...identification import ChunkedDifferences, FitResult, check_fit_data, fit_multistart
from .._docs import docfiller
from . import model as chua
from .box import (
    fit_bounds,
    random_params,
)

fill_doc = docfiller()

__all__ = ["default_starts", "fit_chua", "random_params"]

_ELEMENT_NAMES = ("log_k0", "log_k_inf", "log_y_s", "log_g", "log_v_g", "delta")


def _theta_names(n_elements: int) -> list[str]:
    """Names of the optimiser coordinates (:meth:`ChuaParams.to_vector`), elements from 1."""
    return [f"{name}[{k}]" for k in range(1, n_elements + 1) for name in _ELEMENT_NAMES]


def _theta_limits(n_elements: int) -> tuple[list[str | None], list[str | None]]:
    """Which bounds are limits of the model itself, with a note for each.

    * ``delta_k = 0``: the document's model (no dead band); a band cannot be narrower.
    * ``log g_k`` at its upper bound: beyond the Euler cap ``g`` is a straight line of the
      capped slope, so a larger ``G`` changes nothing (see ``fit_bounds``).

    Every other bound is a search box: a fit there is reported as on bounds.
    """
    lower: list[str | None] = []
    upper: list[str | None] = []
    for k in range(1, n_elements + 1):
        lower += [None] * 5 + [f"element {k} has no dead band (delta = 0, the document's model)"]
        cap = f"element {k} runs at the Euler slope cap (a larger G changes nothing)"
        upper += [None] * 3 + [cap, None, None]
    return lower, upper


def default_starts(structure: chua.ChuaStructure, gain: float) -> list[chua.ChuaParams]:
    """Deterministic starts: linear restoring functions sharing the static ``gain`` (output per
    input), element rates at 5 and 50 per cent of the Euler cap spread by 6x between elements,
    with and without a dead band, strongly and mildly non-linear ``g``.

    Parameters
    ----------
    structure : chua.ChuaStructure
        The model's structure.
    gain : float
        Static gain (output per input).

    Returns
    -------
    list of chua.ChuaParams
        The starts.
    """
    n = structure.n_elements
    k = np.full(n, n / gain)
    spread = 6.0 ** (np.arange(n) - (n - 1) / 2)
    starts = []
    for frac in (0.05, 0.5):
        rate = np.minimum(frac * structure.slope_cap / structure.dt * spread,
                          0.9 * structure.slope_cap / structure.dt)
        for delta in (0.0, 0.1):
            for v_g in (0.3, 3.0):
                g = np.clip(rate / k, *chua.DOMAIN["g"])
                starts.append(chua.ChuaParams(k0=k, k_inf=k, y_s=np.full(n, 0.5), g=g,
                                              v_g=np.full(n, v_g), delta=np.full(n, delta)))
    return starts


@fill_doc
def fit_chua(u: np.ndarray, y: np.ndarray, structure: chua.ChuaStructure, *,
             starts: list[chua.ChuaParams] | None = None, max_nfev: int = 100,
             screen_nfev: int = 10, n_polish: int = 2,
             accept: Callable[[chua.ChuaParams], bool] | None = None,
             accept_reason: str = "rejected by the acceptance test",
             solver: str = "tr", loss: str = "linear", f_scale: float = 1.0,
             weights: np.ndarray | None = None) -> FitResult:
    """Fit a Chua-Stromsmoe model mapping ``u`` to ``y`` (SSE, eq. 5.9).

    Parameters
    ----------
    u, y : array, shape (n,)
        Input and target, sampled every ``structure.dt``, centred and normalised (eq. 5.10).
    structure : chua.ChuaStructure
        The model's structure (``N`` elements).
    starts : list of ChuaParams, optional
        Default :func:`default_starts` (8 starts) with the least-squares static gain.
    max_nfev, screen_nfev, n_polish : int
        Passed to ``fit_multistart`` (iterations of the solver; each finite-difference
        Jacobian costs another 6N model runs).
    accept, accept_reason
        Candidates for which ``accept(params)`` is false are skipped.
    solver : {"tr", "lm", "trf"}
        See :func:`hystkit.identification.fit_multistart` ("trf": dense difference Jacobian).
    loss, f_scale, weights
        The cost minimised: the SSE by default, or a robust loss and/or per-sample weights
        (one per sample of ``y``); see :func:`hystkit.identification.fit_multistart`.

    %(best_start)s

    Raises
    ------
    ValueError
        If there are no more samples than parameters (``6 N``).
    FitDivergedError
        If no start gives a finite cost or every candidate is vetoed.
    """
    u, y = check_fit_data(u, y)
    n = structure.n_elements
    if u.size <= structure.n_params:
        raise ValueError(f"a Chua-Stromsmoe fit with {n} elements needs more samples than its "
                         f"{structure.n_params} parameters, got {u.size}")
    if starts is None:
        # f and g increase, so the static gain is positive; a floor keeps k finite
        gain = min(max(float(np.polyfit(u, y, 1)[0]), 0.05), 1e4)  # k within the domain
        starts = default_starts(structure, gain)

    def to_params(theta: np.ndarray) -> chua.ChuaParams:
        return chua.ChuaParams.from_vector(theta, n)

    bounds = fit_bounds(structure)
    chunked = ChunkedDifferences(
        lambda th, u_chunk, x: chua.simulate(structure, to_params(th), u_chunk, x), u, y,
        *bounds)
    return fit_multistart(lambda th: chua.simulate(structure, to_params(th), u)[0] - y,
                          [p.to_vector() for p in starts], bounds, to_params,
                          structure, normal_equations=chunked.normal_equations,
                          cost=chunked.cost, solver=solver, max_nfev=max_nfev,
                          screen_nfev=screen_nfev, n_polish=n_polish, accept=accept,
                          accept_reason=accept_reason, names=_theta_names(n),
                          limits=_theta_limits(n), loss=loss, f_scale=f_scale,
                          weights=weights)


