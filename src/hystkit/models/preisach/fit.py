"""Identification of the classical Preisach model (sec. 2.1.1, appendix 9.3-9.5).

Identification from first-order reversal curves (appendix 9.4, eq. 9.4):
:func:`everett_from_forcs`. Without FORCs, :func:`fit_preisach` (the family's fit): the
output is linear in the cell masses of the grid (``y = Phi @ m + y_0``, ``Phi`` from
:func:`hystkit.models.preisach.cell_regressors`), so the SSE of eq. 5.9 is minimised by one
bounded linear least-squares solve (:func:`bounded_lstsq`: ``scipy.optimize.nnls``, checked,
BVLS as the fallback) per loop orientation:

- counter-clockwise loops (the output lags the input, e.g. position -> sensor): all masses
  ``>= 0``, i.e. ``mu >= 0``: monotone branches and an exact inverse;
- clockwise loops (the inverse of such a hysteresis, e.g. sensor -> position): off-diagonal
  masses ``<= 0``, diagonal (zero-width, reversible) masses ``>= 0``. A non-negative Preisach
  weight cannot make clockwise loops at all, so a direct compensator needs this sign.

``orientation="auto"`` (default) solves both and keeps the lower SSE. Cells that the data
never switch independently are not determined by the SSE alone; a smoothness penalty fixes
them::

    minimise  ||Phi m + y_0 - y||^2 + smoothing * n * sum_{neighbour cells} (rho_a - rho_b)^2

with ``rho`` the density (mass per area on the grid squares, per length along the diagonal
segments): a discrete integral of ``|grad mu|^2``, nearly independent of the grid size, per
sample. ``smoothing = 0`` gives plain bounded least squares.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.interpolate import LinearNDInterpolator
from scipy.linalg import LinAlgError, LinAlgWarning
from scipy.optimize import lsq_linear, nnls

from ..._blas import one_blas_thread
from ...errors import FitDivergedError
from ...identification import (
    FitResult,
    FitTimer,
    check_fit_data,
    check_weights,
    require_linear_loss,
)
from .._docs import docfiller
from . import model as preisach

fill_doc = docfiller()

__all__ = ["KKT_RTOL", "ORIENTATIONS", "SUPPORTED_LOSSES", "bounded_lstsq", "check_data",
           "everett_from_forcs", "fit_oriented", "fit_preisach", "kkt_holds", "smoothness_rows",
           "solve_regularised"]


def check_data(u: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """1-D, equal length, finite; returned as contiguous float arrays.

    Parameters
    ----------
    u, y : numpy.ndarray, shape (n,)
        Input and target output.

    Returns
    -------
    u, y : numpy.ndarray, shape (n,)
        The same, contiguous float64.
    """
    return check_fit_data(u, y, min_size=2)


def smoothness_rows(levels: int) -> np.ndarray:
    """Penalty rows ``D`` with ``||D m||^2 = sum (rho_a - rho_b)^2`` over neighbouring cells.

    Squares (density ``m / h^2``) neighbour squares, diagonal segments (density ``m / h``,
    weighted by ``h^-1/2`` for the 1-D integral) neighbour diagonal segments; ``h`` is the grid
    step. Columns follow ``np.tril_indices(levels - 1)``.

    Parameters
    ----------
    levels : int
        Grid levels ``L``.

    Returns
    -------
    array, shape (n_pairs, L (L - 1) / 2)
    """
    h = 2.0 / (levels - 1)
    rows, cols = np.tril_indices(levels - 1)
    index = {(i, j): k for k, (i, j) in enumerate(zip(rows, cols))}
    pairs, scales = [], []
    for (i, j), k in index.items():
        if j < i:
            for nb in ((i + 1, j), (i, j + 1)):
                if nb in index and nb[1] < nb[0]:
                    pairs.append((k, index[nb]))
                    scales.append(h ** -2)
        elif (i + 1, i + 1) in index:
            pairs.append((k, index[(i + 1, i + 1)]))
            scales.append(h ** -1.5)
    d = np.zeros((len(pairs), rows.size))
    for r, ((a, b), scale) in enumerate(zip(pairs, scales)):
        d[r, a], d[r, b] = scale, -scale
    return d


KKT_RTOL = 1e-10
"""KKT violation :func:`kkt_holds` accepts, relative to the gradient's rounding scale ``|r|^T
(|r| |x| + |b|)`` (rounding: ~``p eps`` of it, <= 1e-12 on the largest grid; 1e-15 seen): no entry
leaving its bound could lower ``||r x - b||^2`` by more than ``KKT_RTOL^2 || |r||x| + |b| ||^2``."""


def kkt_holds(r: np.ndarray, b: np.ndarray, x: np.ndarray, nonneg: np.ndarray) -> bool:
    """Whether `x` solves ``min ||r x - b||``, ``x[nonneg] >= 0``, to within rounding: the
    gradient ``g = r^T (r x - b)`` vanishes off the bounds and is >= 0 on them (`KKT_RTOL`).

    Parameters
    ----------
    r, b, x, nonneg : numpy.ndarray, shapes (k, p), (k,), (p,) and (p,) (bool)

    Returns
    -------
    bool
        False also for a non-finite `x`.
    """
    g = r.T @ (r @ x - b)
    scale = np.abs(r).T @ (np.abs(r) @ np.abs(x) + np.abs(b))
    violation = np.where(nonneg & (x <= 0.0), -g, np.abs(g))  # on a bound: g >= 0 is fine
    return bool(np.all(x[nonneg] >= 0.0) and np.all(violation <= KKT_RTOL * scale))


def bounded_lstsq(r: np.ndarray, b: np.ndarray,
                  nonneg: np.ndarray) -> tuple[np.ndarray, str, bool]:
    """``argmin ||r x - b||`` with ``x[nonneg] >= 0``: nnls, checked; BVLS if the check fails.

    scipy's ``nnls`` (Lawson-Hanson, each free column split in two: ``x = z+ - z-``) updates a
    factorisation per active-set change where BVLS solves a dense ``lstsq`` each time (~30x
    less CPU at twice the default grid: ``benchmarks/bench_preisach_fit.py``). nnls was
    rewritten in scipy 1.12, 1.15 and 1.16 and has returned non-optimal points (scipy issue
    25389): its answer is kept only if :func:`kkt_holds`, else BVLS (``lsq_linear``) solves.

    Parameters
    ----------
    r, b, nonneg : numpy.ndarray, shapes (k, p), (k,) and (p,) (bool)

    Returns
    -------
    x : array, shape (p,)
    message : str
        Which solver answered (shown as the fit's solver message).
    success : bool
    """
    free, p = ~nonneg, r.shape[1]
    try:
        with warnings.catch_warnings():  # an ill-conditioned active set may warn: checked below
            warnings.simplefilter("ignore", LinAlgWarning)
            z, _ = nnls(np.hstack([r, -r[:, free]]), b)
        x = z[:p].copy()
        x[free] -= z[p:]
        if kkt_holds(r, b, x, nonneg):
            return x, "nnls (scipy), optimality checked", True
        why = "nnls failed the optimality check"
    except (RuntimeError, LinAlgError) as exc:  # RuntimeError: its iteration limit
        why = f"nnls: {exc}"
    sol = lsq_linear(r, b, bounds=(np.where(nonneg, 0.0, -np.inf), np.inf), method="bvls",
                     tol=1e-12)
    x = sol.x.copy()
    x[nonneg] = np.maximum(x[nonneg], 0.0)  # bvls may leave -0.0 or -1e-17 at the bound
    return x, f"bvls ({why}): {sol.message}", bool(sol.success)


def solve_regularised(a: np.ndarray, y: np.ndarray, penalty: np.ndarray,
                      nonneg: np.ndarray) -> tuple[np.ndarray, str, bool]:
    """``argmin ||a x - y||^2 + ||penalty x||^2`` with ``x[nonneg] >= 0``.

    The stacked problem is first reduced to its triangular QR factor (``||a x - y||^2`` equals
    ``||R x - Q^T y||^2`` plus a constant), so the bounded solver (:func:`bounded_lstsq`)
    works on a square problem whatever the number of samples.

    Parameters
    ----------
    a : numpy.ndarray, shape (n, p)
        Design matrix.
    y : numpy.ndarray, shape (n,)
        Target.
    penalty : numpy.ndarray, shape (m, p)
        Regularisation rows.
    nonneg : numpy.ndarray of bool, shape (p,)
        Entries of `x` constrained to be non-negative.

    Returns
    -------
    x : array, shape (p,)
    message : str
    success : bool
    """
    with one_blas_thread():
        stacked = np.vstack([np.column_stack([a, y]),
                             np.column_stack([penalty, np.zeros(penalty.shape[0])])])
        r = np.linalg.qr(stacked, mode="r")
        p = a.shape[1]
        return bounded_lstsq(r[:p, :p], r[:p, p], nonneg)


ORIENTATIONS = {"counterclockwise": (1.0,), "clockwise": (-1.0,), "auto": (1.0, -1.0)}
SUPPORTED_LOSSES = ("linear",)
"""Costs :func:`fit_preisach` minimises: the (weighted) SSE only (one linear solve)."""


def fit_oriented(a: np.ndarray, y: np.ndarray, penalty: np.ndarray, hysteretic: np.ndarray,
                 nonneg: np.ndarray, orientation: str, to_params: Callable[[np.ndarray], Any],
                 structure: Any, accept: Callable[[Any], bool] | None,
                 accept_reason: str, weights: np.ndarray | None = None) -> FitResult:
    """Solve the linear fit for each loop orientation; return the cheapest accepted one.

    The columns ``hysteretic`` (off-diagonal Preisach cells) get the orientation's sign
    before the solve, so ``x[nonneg] >= 0`` means non-negative weights for counter-clockwise
    loops and non-positive ones for clockwise loops; see the module docstring.

    Parameters
    ----------
    a : numpy.ndarray, shape (n, p)
        Design matrix.
    y : numpy.ndarray, shape (n,)
        Target output.
    penalty : numpy.ndarray, shape (m, p)
        Regularisation rows.
    hysteretic : numpy.ndarray of bool, shape (p,)
        Columns whose sign follows the loop orientation.
    nonneg : numpy.ndarray of bool, shape (p,)
        Columns constrained to be non-negative (after the orientation's sign).
    orientation : {"counterclockwise", "clockwise", "auto"}
        Orientations to try.
    to_params : callable
        Coefficients -> the family's parameters.
    structure : object
        The family's structure, for the result.
    accept : callable or None
        A solution counts only if ``accept(params)`` is true.
    accept_reason : str
        The message when every solution is rejected.
    weights : numpy.ndarray, shape (n,), optional
        Per-sample weights: rows of `a` and `y` scaled by ``sqrt(w)``, `penalty` by
        ``sqrt(mean(w))``; the solutions are ranked by the weighted SSE.

    Returns
    -------
    FitResult
        The cheapest accepted solution; its ``cost`` is the plain SSE, its ``objective`` the
        weighted one.

    Raises
    ------
    FitDivergedError
        If every solution is rejected.
    ValueError
        If `weights` are not one finite value >= 0 per sample, not all 0.
    """
    timer = FitTimer()
    a_w, y_w, penalty_w = a, y, penalty
    if weights is not None:
        weights = check_weights(weights, y.size)
        root = np.sqrt(weights)
        a_w, y_w = a * root[:, None], y * root
        penalty_w = penalty * np.sqrt(np.mean(weights))
    candidates = []
    for sign in ORIENTATIONS[orientation]:
        flip = np.where(hysteretic, sign, 1.0)
        coef, message, success = solve_regularised(a_w * flip, y_w, penalty_w * flip, nonneg)
        coef *= flip
        r = a @ coef - y
        sse = float(r @ r)
        candidates.append((sse if weights is None else float(weights @ (r * r)), sse, sign,
                           coef, message, success))
    candidates.sort(key=lambda cand: cand[0])
    rejected = 0
    for objective, cost, sign, coef, message, success in candidates:
        params = to_params(coef)
        if accept is not None and not accept(params):
            rejected += 1
            continue
        loops = "counter-clockwise" if sign > 0 else "clockwise"
        return FitResult(structure=structure, params=params, cost=cost, n_evaluations=1,
                         seconds=timer.seconds(), converged=success,
                         message=f"{loops} loops; {message}", n_starts=len(candidates),
                         objective=objective, weighted=weights is not None)
    raise FitDivergedError(f"the fit failed: all {rejected} least-squares solutions were "
                           f"rejected ({accept_reason})")


@fill_doc
def fit_preisach(u: np.ndarray, y: np.ndarray, structure: preisach.PreisachStructure, *,
                 accept: Callable[[preisach.PreisachParams], bool] | None = None,
                 accept_reason: str = "rejected by the acceptance test", loss: str = "linear",
                 f_scale: float = 1.0, weights: np.ndarray | None = None) -> FitResult:
    """Fit the classical Preisach model mapping ``u`` to ``y`` (linear least squares, eq. 5.9).

    Parameters
    ----------
    u, y : array, shape (n,)
        Model input and target output, centred and normalised (eq. 5.10) by the caller; the
        model starts in its default (demagnetised) state, as :func:`preisach.simulate` does.
    structure : PreisachStructure
        ``levels`` sets the grid, ``smoothing`` the penalty and ``orientation`` the sign of
        the hysteretic weights (module docstring).
    accept : callable, optional
        Checked on each solution (one per orientation tried), cheapest first; vetoed ones are
        skipped.
    accept_reason : str, optional
        The message when every solution is rejected.
    %(linear_loss)s
    %(penalised_weights)s

    Returns
    -------
    FitResult
        The cheapest accepted solution.

    Raises
    ------
    FitDivergedError
        If ``accept`` rejects every solution (with ``accept_reason``).
    InputError
        If `loss` is a robust loss.
    """
    require_linear_loss(loss, f_scale, "preisach", "linear least squares")
    u, y = check_data(u, y)
    levels = structure.levels
    phi = preisach.cell_regressors(levels, u, capacity=structure.capacity)
    # beyond [-1, 1] the slope F(1, -1) is the total mass: every cell carries the extension
    phi += (u - np.clip(u, -1.0, 1.0))[:, None]
    a = np.column_stack([phi, np.ones(u.size)])
    d = smoothness_rows(levels) * np.sqrt(structure.smoothing * u.size)
    penalty = np.column_stack([d, np.zeros(d.shape[0])])  # the offset is not penalised
    rows, cols = np.tril_indices(levels - 1)
    hysteretic = np.r_[rows != cols, False]
    nonneg = np.r_[np.ones(rows.size, bool), False]

    def to_params(coef: np.ndarray) -> preisach.PreisachParams:
        masses = np.zeros((levels - 1, levels - 1))
        masses[rows, cols] = coef[:-1]
        return preisach.PreisachParams.from_masses(masses, offset=coef[-1])

    return fit_oriented(a, y, penalty, hysteretic, nonneg, structure.orientation, to_params,
                        structure, accept, accept_reason, weights)


def everett_from_forcs(alphas: np.ndarray, betas: np.ndarray, y: np.ndarray,
                       levels: int | None = None) -> preisach.PreisachParams:
    """Identify the model from first-order reversal curves (eq. 9.4, appendix 9.4).

    FORC ``i`` starts in negative saturation, rises to ``alphas[i]`` (the limiting ascending
    branch, ``f_alpha``) and falls through ``betas[j] <= alphas[i]``, giving
    ``y[i, j] = f_{alpha_i beta_j}``. Then ``F(alpha, beta) = (f_alpha - f_alpha beta) / 2``
    (eq. 9.4), with ``f_alpha`` read where ``beta = alpha``, and ``y_0`` is the mean of the
    FORC from 1 at its two ends, ``(f+ + f-) / 2``. ``F`` is resampled onto the model's grid by
    piecewise-linear interpolation over the measured points (exact at shared nodes).

    Parameters
    ----------
    alphas : array, shape (n_a,)
        Reversal inputs, strictly increasing, including -1 and 1.
    betas : array, shape (n_b,)
        Measuring inputs, strictly increasing; must contain every alpha.
    y : array, shape (n_a, n_b)
        FORC outputs; entries with ``betas[j] > alphas[i]`` are ignored.
    levels : int, optional
        Model grid levels; default ``n_a``.

    Returns
    -------
    preisach.PreisachParams
        Everett nodes on the model grid and the offset ``y_0``.
    """
    alphas, betas = np.asarray(alphas, dtype=float), np.asarray(betas, dtype=float)
    y = np.asarray(y, dtype=float)
    if y.shape != (alphas.size, betas.size):
        raise ValueError(f"y must have shape {(alphas.size, betas.size)}, got {y.shape}")
    if np.any(np.diff(alphas) <= 0) or np.any(np.diff(betas) <= 0):
        raise ValueError("alphas and betas must be strictly increasing")
    if alphas[0] != -1.0 or alphas[-1] != 1.0 or betas[0] != -1.0:
        raise ValueError("the FORCs must cover the input range: alphas from -1 to 1, betas "
                         "from -1")
    start = np.searchsorted(betas, alphas)
    if np.any(start >= betas.size) or np.any(betas[np.minimum(start, betas.size - 1)]
                                             != alphas):
        raise ValueError("betas must contain every alpha (each FORC's first point)")
    ia, ib = np.nonzero(betas[None, :] <= alphas[:, None])
    values = 0.5 * (y[ia, start[ia]] - y[ia, ib])  # eq. 9.4
    if not np.all(np.isfinite(values)):
        raise ValueError("y must be finite where betas <= alphas")
    points = np.column_stack([alphas[ia], betas[ib]])
    levels = alphas.size if levels is None else int(levels)
    h = preisach.grid(levels)
    na, nb = np.tril_indices(levels, -1)
    e = np.zeros((levels, levels))
    e[na, nb] = LinearNDInterpolator(points, values)(h[na], h[nb])
    offset = 0.5 * (y[-1, start[-1]] + y[-1, 0])
    return preisach.PreisachParams(everett=e, offset=offset)
