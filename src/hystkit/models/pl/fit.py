"""Identification of the Power-Law model as published (sec. 2.1.7, eq. 2.16-2.18) for a fixed
structure; the structural search over N, p, M, S (table 5.1) is in ``search.py``.

Fit for a fixed structure. The document (sec. 2.2) obtains the weights by "minimizing the
constrained quadratic cost function" of its ref. [15]. The cost is quadratic because it is
posed on the resistor's voltage side: with the measured current ``y``,
``f(y) = sum a_j phi_j(y)`` must equal ``w_0 e + sum w_k u_k - V_b`` (eq. 2.17-2.18), which is
linear in ``a``, ``w`` and ``V_b`` once the cell voltages ``u_k`` are simulated. Here that
equation error is solved by bounded linear least squares, with

* the scale fixed by a constraint, mean slope of ``f`` on [-1, 1] equal to 1 (``sum a_j = M``),
  because scaling ``a``, ``w`` and ``V_b`` together leaves ``i = f^-1(u)`` unchanged;
* ``a_j >= 0.05`` so that ``f`` stays invertible, ``|w| <= 100`` (sec. 5.3.3's weight bound);
* ``S`` times the squared slope changes ``a_j+1 - a_j`` added per sample (our reading of S).

The two resistor parameters ``I_T`` and ``V_T`` enter non-linearly; ``fit_multistart`` moves
them (log coordinates) with the output error ``f^-1(...) - y`` (eq. 5.9) as its residual, the
weights being re-solved at every evaluation (variable projection). N, p, M and S are not
fitted by least squares: ``search.structural_search`` tries every combination of a grid.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import lsq_linear

from ...identification import FitResult, check_fit_data, check_weights, fit_multistart
from .._docs import docfiller
from . import model as pl
from .box import (
    A_MIN,
    LOG_IT,
    LOG_VT,
    W_BOUND,
    random_params,
)

fill_doc = docfiller("pl.PlStructure")

__all__ = ["THETA_NAMES", "default_starts", "fit_pl", "random_params", "solve_weights"]

# The optimiser coordinates. Both bounds are search boxes (the Euler slope cap acts through the
# straight branches of the characteristic, not through a bound), so no model limits are passed.
THETA_NAMES = ("log_i_t", "log_v_t")

def solve_weights(structure: pl.PlStructure, x: np.ndarray, u: np.ndarray,
                  y: np.ndarray, weights: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray, float]:
    """Constrained quadratic fit of ``a``, ``w``, ``V_b`` on the voltage side (see module doc).

    Parameters
    ----------
    structure : pl.PlStructure
        The model's structure.
    x : array, shape (n, N)
        Cell voltages at every sample.
    u, y : array, shape (n,)
        Source voltage and measured output current.
    weights : array, shape (n,), optional
        Per-sample weights: each sample's row scaled by ``sqrt(w)``, the smoothing rows by
        ``sqrt(mean(w))`` (weights all equal to any ``c`` give the unweighted fit).

    Returns
    -------
    a : array, shape (M,)
    w : array, shape (N + 1,)
    v_b : float
    """
    n, m = y.size, structure.n_basis
    brk = pl.basis_breakpoints(m)
    lo, hi = np.r_[-np.inf, brk[1:-1]], np.r_[brk[1:-1], np.inf]
    phi = np.clip(y[:, None], lo, hi) - np.clip(0.0, lo, hi)
    # unknowns [a_1..a_M, w_0..w_N, V_b]: phi a - e w_0 - X w + V_b = 0
    rows = [np.column_stack([phi, -u, -x, np.ones(n)])]
    mean_weight = 1.0
    if weights is not None:
        rows[0] *= np.sqrt(weights)[:, None]
        mean_weight = float(np.mean(weights))
    rhs = [np.zeros(n)]
    width = rows[0].shape[1]
    if m > 1 and structure.smoothing > 0:
        diff = np.zeros((m - 1, width))
        diff[np.arange(m - 1), np.arange(m - 1)] = -1.0
        diff[np.arange(m - 1), np.arange(1, m)] = 1.0
        rows.append(np.sqrt(structure.smoothing * n * mean_weight) * diff)
        rhs.append(np.zeros(m - 1))
    # the scale constraint as a heavily weighted row (exact to ~1e-8 relative)
    heavy = 1e4 * np.sqrt(n * mean_weight)
    constraint = np.zeros((1, width))
    constraint[0, :m] = heavy
    rows.append(constraint)
    rhs.append(np.array([heavy * m]))
    lower = np.r_[np.full(m, A_MIN), np.full(structure.n_cells + 1, -W_BOUND), -np.inf]
    upper = np.r_[np.full(m, np.inf), np.full(structure.n_cells + 1, W_BOUND), np.inf]
    sol = lsq_linear(np.vstack(rows), np.concatenate(rhs), bounds=(lower, upper),
                     method="bvls", lsmr_tol=None)
    coef = np.clip(sol.x, lower, upper)
    return coef[:m], coef[m:-1], float(coef[-1])


@fill_doc
def default_starts(structure: pl.PlStructure) -> list[np.ndarray]:
    """Starts ``[log I_T, log V_T]``: a coarse grid of the two, thresholds spanning 0.2 to 2 of
    the normalised range (``N V_T``) and cell-1 creep time constants ``V_T / I_T`` of 0.3, 3
    and 30 s (12 starts; the cost has several basins in these two coordinates).

    %(structure_parameters)s

    Returns
    -------
    list of numpy.ndarray
        The starts, each ``[log I_T, log V_T]``.
    """
    starts = []
    for span in (0.2, 0.5, 1.0, 2.0):
        v_t = span / structure.n_cells
        for tau in (0.3, 3.0, 30.0):
            starts.append(np.log([v_t / tau, v_t]))
    return starts


@fill_doc
def fit_pl(u: np.ndarray, y: np.ndarray, structure: pl.PlStructure, *,
           starts: list[np.ndarray] | None = None, max_nfev: int = 40, screen_nfev: int = 4,
           n_polish: int = 2, accept: Callable[[pl.PlParams], bool] | None = None,
           accept_reason: str = "rejected by the acceptance test",
           solver: str = "tr", loss: str = "linear", f_scale: float = 1.0,
           weights: np.ndarray | None = None) -> FitResult:
    """Fit the weights, bias, output resistor and ``I_T``, ``V_T`` for a fixed structure.

    Parameters
    ----------
    u, y : array, shape (n,)
        Centred, normalised data (eq. 5.10) every ``structure.dt``.
    structure : pl.PlStructure
        The fixed structure.
    starts : list of arrays ``[log I_T, log V_T]``, optional
        Default :func:`default_starts` (12 starts).
    %(multistart)s
    solver : {"tr", "lm", "trf"}
        See :func:`hystkit.identification.fit_multistart`. Variable projection leaves two
        coordinates, so their difference Jacobian (``n x 2``) is formed densely.
    loss, f_scale, weights
        The cost minimised: the SSE by default, or a robust loss and/or per-sample weights
        (one per sample of ``y``); see :func:`hystkit.identification.fit_multistart`. The
        loss acts on ``I_T``, ``V_T`` only: the projected ``a``, ``w``, ``V_b`` stay the
        voltage-side least-squares fit, with its rows weighted by `weights`.

    %(best_start)s

    Raises
    ------
    FitDivergedError
        If no start gives a finite cost or every candidate is vetoed.
    """
    u, y = check_fit_data(u, y)
    if weights is not None:
        weights = check_weights(weights, y.size)
    cache: dict = {}

    def project(theta: np.ndarray) -> tuple[pl.PlParams, np.ndarray]:
        key = theta.tobytes()
        if key not in cache:
            i_t, v_t = np.exp(theta)
            probe = pl.PlParams(i_t=i_t, v_t=v_t, w=np.zeros(structure.n_cells + 1),
                                a=np.ones(structure.n_basis))
            x, _ = pl.states(structure, probe, u)
            a, w, v_b = solve_weights(structure, x, u, y, weights)
            params = pl.PlParams(i_t=i_t, v_t=v_t, w=w, v_b=v_b, a=a)
            cache.clear()
            cache[key] = params, pl.simulate(structure, params, u)[0] - y
        return cache[key]

    lower = np.array([LOG_IT[0], LOG_VT[0]])
    upper = np.array([LOG_IT[1], LOG_VT[1]])
    return fit_multistart(lambda th: project(th)[1],
                          default_starts(structure) if starts is None else starts,
                          (lower, upper), lambda th: project(th)[0], structure,
                          max_nfev=max_nfev, screen_nfev=screen_nfev, n_polish=n_polish,
                          accept=accept, accept_reason=accept_reason, names=THETA_NAMES,
                          solver=solver, loss=loss, f_scale=f_scale, weights=weights)


