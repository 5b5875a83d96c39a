"""Identification of the PWL ladder circuit (Parodi-Storace-Cincotti, sec. 2.1.5).

The read-out weights and bias enter the output linearly, so the SSE (eq. 5.9) is minimised by
variable projection: ``fit_multistart`` moves only the resistor parameters (per cell the dead
band ``E_k`` and ``log G_k``), and every residual evaluation solves the weights and bias by
linear least squares on the simulated capacitor voltages (finite-difference Jacobian). A robust
loss or per-sample weights (``loss``, ``weights``) apply to both: the outer solver minimises the
robust cost of the projected residual, and the projection solves the weights and bias for the
same cost (weighted rows; iteratively reweighted for a robust loss).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...identification import (
    FitResult,
    check_cost,
    check_fit_data,
    check_weights,
    fit_multistart,
    robust_linear_fit,
)
from .._docs import docfiller
from . import model as ladder
from .box import (
    BAND,
    LOG_G_MIN,
    W_BOUND,
    random_params,
)

fill_doc = docfiller("ladder.LadderStructure")

__all__ = ["default_starts", "fit_ladder", "random_params"]


def _theta_names(n_cells: int) -> list[str]:
    """Names of the optimiser coordinates ``[E_1, log G_1, .., E_N, log G_N]``, cells from 1."""
    return [f"{name}[{k}]" for k in range(1, n_cells + 1) for name in ("E", "log_G")]


def _theta_limits(n_cells: int) -> tuple[list[str | None], list[str | None]]:
    """Which bounds are limits of the model itself, with a note for each.

    * ``E_k = 0``: a dead band cannot be narrower than none; the cell is a linear resistor.
    * ``E_k`` at its upper bound (1.5, beyond the normalised data's range, eq. 5.10): the cell
      never conducts, and a wider band changes nothing.
    * ``log G_k`` at its upper bound: the Euler limit of two conducting resistors at a node
      (:func:`~.model.conductance_limit`), the edge of the family's domain.

    The floor of ``log G_k`` is a search box: a fit there is reported as on bounds.
    """
    lower: list[str | None] = []
    upper: list[str | None] = []
    for k in range(1, n_cells + 1):
        lower += [f"cell {k} has no dead band (E = 0: a linear resistor)", None]
        upper += [f"cell {k}'s dead band covers the data's range (it never conducts)",
                  f"cell {k} runs at the Euler limit (G dt = slope_cap / 2)"]
    return lower, upper


@fill_doc
def default_starts(structure: ladder.LadderStructure) -> list[np.ndarray]:
    """Deterministic starts ``[E_1, log G_1, ..]``: bands growing along the ladder (0, 0.05 or
    0.2 of the range per cell) and conductances near the limit or 10 and 100 times slower.

    %(structure_parameters)s

    Returns
    -------
    list of numpy.ndarray
        The starts, each ``[E_1, log G_1, .., E_N, log G_N]``.
    """
    n = structure.n_cells
    g_max = ladder.conductance_limit(structure)
    steps = np.arange(1, n + 1) / n
    starts = []
    for band in (0.0, 0.05, 0.2):
        for frac in (0.9, 0.1, 0.01):
            starts.append(np.column_stack([band * steps, np.full(n, np.log(frac * g_max))])
                          .reshape(-1))
    return starts


@fill_doc
def fit_ladder(u: np.ndarray, y: np.ndarray, structure: ladder.LadderStructure, *,
               starts: list[np.ndarray] | None = None, max_nfev: int = 100,
               screen_nfev: int = 10, n_polish: int = 2,
               accept: Callable[[ladder.LadderParams], bool] | None = None,
               accept_reason: str = "rejected by the acceptance test",
               solver: str = "trf", loss: str = "linear", f_scale: float = 1.0,
               weights: np.ndarray | None = None) -> FitResult:
    """Fit a PWL ladder mapping source voltage ``u`` to output ``y`` (SSE, eq. 5.9).

    Parameters
    ----------
    u, y : array, shape (n,)
        Centred, normalised data (eq. 5.10), sampled every ``structure.dt``.
    structure : ladder.LadderStructure
        The model's structure (``N`` sections).
    starts : list of arrays, optional
        Resistor parameters ``[E_1, log G_1, .., E_N, log G_N]``; default
        :func:`default_starts` (9 starts).
    %(multistart)s
    solver : {"trf", "tr", "lm"}
        See :func:`~hystkit.identification.fit_multistart`. scipy's trf stays the default here:
        "tr" reaches the same SSE (to 1e-15 on the virtual sensor), but the inverse 1-cell
        ladder fitted on seed 1 then diverges on seed 2 -- as does trf's own optimum with its
        conductance moved by 1e-9 relative (a knife edge that tests/models/ladder relies on).
        Variable projection keeps the Jacobian at ``n x 2 N``, so trf's cost here is small.
    loss, f_scale, weights
        The cost minimised: the SSE by default, or a robust loss and/or per-sample weights
        (one per sample of ``y``); see :func:`hystkit.identification.fit_multistart`. The
        projected weights and bias minimise the same cost
        (:func:`hystkit.identification.robust_linear_fit`).

    %(best_start)s

    Raises
    ------
    ValueError
        If there are no more samples than parameters (``3 N + 2``).
    FitDivergedError
        If no start gives a finite cost or every candidate is vetoed.
    """
    u, y = check_fit_data(u, y)
    n = structure.n_cells
    if u.size <= structure.n_params:
        raise ValueError(f"a ladder fit with {n} sections needs more samples than its "
                         f"{structure.n_params} parameters, got {u.size}")
    check_cost(loss, f_scale)
    if weights is not None:
        weights = check_weights(weights, y.size)
    lower = np.tile([BAND[0], LOG_G_MIN], n)
    upper = np.tile([BAND[1], np.log(ladder.conductance_limit(structure))], n)
    cache: dict = {}

    def project(theta: np.ndarray) -> tuple[ladder.LadderParams, np.ndarray]:
        # least_squares evaluates the same point again for the acceptance test and the result
        key = theta.tobytes()
        if key not in cache:
            cells = theta.reshape(n, 2)
            probe = ladder.LadderParams(band=cells[:, 0], conductance=np.exp(cells[:, 1]),
                                        w=np.zeros(n + 1))
            states, _ = ladder.states(structure, probe, u)
            design = np.column_stack([u, states, -np.ones_like(u)])
            coef = robust_linear_fit(design, y, loss, f_scale, weights)
            coef[:-1] = np.clip(coef[:-1], -W_BOUND, W_BOUND)
            # V_b is free, but within the domain where runs stay bounded
            coef[-1] = np.clip(coef[-1], -ladder.MAX_VALUE, ladder.MAX_VALUE)
            params = ladder.LadderParams(band=probe.band, conductance=probe.conductance,
                                         w=coef[:-1], v_b=coef[-1])
            cache.clear()
            cache[key] = params, design @ coef - y
        return cache[key]

    return fit_multistart(lambda th: project(th)[1],
                          default_starts(structure) if starts is None else starts,
                          (lower, upper), lambda th: project(th)[0], structure,
                          max_nfev=max_nfev, screen_nfev=screen_nfev, n_polish=n_polish,
                          accept=accept, accept_reason=accept_reason, solver=solver,
                          names=_theta_names(n), limits=_theta_limits(n),
                          loss=loss, f_scale=f_scale, weights=weights)


