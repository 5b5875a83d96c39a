"""Identification of the Kuhnen / modified Prandtl-Ishlinskii model (sec. 2.1.6): one bounded
linear least-squares solve (the document's "quadratic
optimisation", sec. 2.2).

Kuhnen's generalised error. The output ``y = S[H[x] + K[x] + b]`` is bilinear in the dead-zone
and play weights, but the output-side error ``e = S^-1[y] - H[x] - K[x] - b`` is *linear* in
all of them once the inverse superposition operator ``S^-1`` gets fixed thresholds ``d'_k`` in
output units: ``k / (m + 1)`` of the largest and of the smallest output, ``k = 1 .. m``. The
scale shared by ``S^-1`` and ``H + K`` is fixed by a unit slope of ``S^-1`` between ``d'_-1``
and ``d'_1``. ``S`` (forward thresholds and weights) then follows by the inversion formula of
:func:`hystkit.models.pi.inverse_superposition`, which is an involution.

Constraints become bounds by a change of variables: the unknowns are the *slopes* the weights
add up to (partial sums), so "partial sums > 0" (Kuhnen's invertibility condition) is a box.
For ``S^-1`` these are its slopes between thresholds, ``>= MIN_SLOPE``. For ``H + K`` the creep
weights are split, ``w_K = w+ - w-`` with ``w+, w- >= 0``, and the unknowns are
``V_i = W_i - sum_j w-_j >= MIN_SLOPE`` with ``W_i = w_H0 + .. + w_Hi`` the slopes of the
initial loading curve: every slope of ``H`` exceeds the total negative creep. In these
variables ``H + K = sum_i V_i (p_i - p_{i+1}) + sum_j (w+_j z_j + w-_j (x - z_j))``, linear and
box-bounded. The condition keeps the instantaneous operator invertible (``W~_i >= V_i``) and
the inverse stable: for a branch of slope ``W`` the linearised model is ``G(q) = W + sum_j w_Kj
c_j q / (q - 1 + c_j)``, and for ``|q| >= 1`` each creep term has a real part in
``[c_j / (2 - c_j), 1]`` times its weight, so ``Re G >= W - sum_j w-_j > 0``: no zero of the
model, no pole of the compensator, outside the unit circle. Creep of either sign stays possible
-- a direct compensator (sensor -> position) needs negative creep weights, the inverse of the
sensor's creep -- but not the large negative slow weights a free fit uses to chase slow drift,
whose inverse diverges. A decreasing relation is fitted as an increasing one of ``-u``.

``scipy.optimize.lsq_linear`` (BVLS, exact active set) solves the problem in one go. The split
makes the matrix rank deficient (``x = sum_i (p_i - p_{i+1})``) and slopes beyond the input's
travel are not excited at all, so a tiny ridge pulls every unknown towards a neutral value
(slopes 1, creep and offset 0); it does not move well-determined weights measurably.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import lsq_linear

from ..._blas import one_blas_thread
from ...errors import FitDivergedError
from ...identification import FitResult, FitTimer, check_weights, require_linear_loss
from . import kernels
from . import model as pi
from .box import (
    MIN_SLOPE,
    make_structure,
    params_from_theta,
)

__all__ = ["MIN_SLOPE", "SUPPORTED_LOSSES", "fit_pi", "make_structure", "output_thresholds"]

SUPPORTED_LOSSES = ("linear",)
"""Costs :func:`fit_pi` minimises: the (weighted) squared generalised error only (one bounded
linear solve)."""


def output_thresholds(y: np.ndarray, n_deadzone: int) -> np.ndarray:
    """Thresholds ``d'`` of ``S^-1``, shape (2 m + 1,): ``k / (m + 1)`` of the output's extremes.

    Kuhnen spreads them equidistantly over the output range; a side without data (an output
    that never changes sign) gets the mirror of the other side.

    Parameters
    ----------
    y : numpy.ndarray, shape (n,)
        Target output.
    n_deadzone : int
        Dead zones per side, ``m``.

    Returns
    -------
    numpy.ndarray, shape (2 m + 1,)
        The thresholds, ascending.

    Raises
    ------
    ValueError
        If `y` is identically 0.
    """
    hi, lo = float(np.max(y)), float(np.min(y))
    span = max(hi, -lo)
    if span == 0:
        raise ValueError("y is identically 0: there is no output range to place S^-1 in")
    hi = hi if hi > 0 else span
    lo = lo if lo < 0 else -span
    k = np.arange(1, n_deadzone + 1) / (n_deadzone + 1)
    return np.concatenate([lo * k[::-1], [0.0], hi * k])


def _ramps(y: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centre part of ``y`` (unit slope) and its part in each outer interval of ``d``."""
    m = (d.size - 1) // 2
    if m == 0:
        return y.copy(), np.empty((y.size, 0))
    edges_hi = np.append(d[m + 1:], np.inf)
    edges_lo = np.insert(d[:m], 0, -np.inf)
    up = np.clip(y[:, None] - edges_hi[None, :-1], 0.0, np.diff(edges_hi)[None, :])
    down = np.clip(y[:, None] - edges_lo[None, 1:], -np.diff(edges_lo)[None, :], 0.0)
    return np.clip(y, d[m - 1], d[m + 1]), np.hstack([up, down[:, ::-1]])


def fit_pi(u: np.ndarray, y: np.ndarray, structure: pi.PiStructure, *,
           accept: Callable[[pi.PiParams], bool] | None = None,
           accept_reason: str = "rejected by the acceptance test",
           d_inv: np.ndarray | None = None, ridge: float = 1e-9, loss: str = "linear",
           f_scale: float = 1.0, weights: np.ndarray | None = None) -> FitResult:
    """Fit a modified PI model mapping ``u`` to ``y`` by Kuhnen's generalised error.

    Parameters
    ----------
    u, y : array, shape (n,)
        Model input and target output, sampled every ``structure.dt``, centred and normalised
        (eq. 5.10) by the caller. The model starts at rest at ``u[0]`` (the default state).
    structure : PiStructure
    accept : callable, optional
        Checked once on the solution; a veto raises FitDivergedError with ``accept_reason``.
    accept_reason : str, optional
        The message of a veto.
    d_inv : array, shape (2 n_deadzone + 1,), optional
        Thresholds of ``S^-1`` in output units; default :func:`output_thresholds`.
    ridge : float
        Adds ``ridge * n * |theta - neutral|^2`` to the squared generalised error: a pull of
        every unknown towards a neutral value (slopes 1, creep weights and offset 0) that is
        ``ridge`` times the energy of a unit-variance regressor. The default 1e-9 only decides
        what the data leave open.
    loss, f_scale : str, float
        Only ``"linear"``: a robust loss is refused with InputError.
    weights : array, shape (n,), optional
        Per-sample weights (finite, >= 0, not all 0): the generalised error of sample ``i``
        counts ``w_i`` times (its row scaled by ``sqrt(w_i)``), the ridge ``mean(w)`` times.

    Returns
    -------
    FitResult
        ``cost`` is the output SSE (eq. 5.9) of the fitted model, not the generalised error;
        with weights, ``objective`` is the weighted output SSE (the solve minimised the
        weighted generalised error).

    Raises
    ------
    ValueError
        If the data are not finite 1-D pairs or there are no more samples than unknowns.
    FitDivergedError
        If the solution is not finite, leaves the parameter domain (``MAX_VALUE``) or is
        vetoed by ``accept``.
    """
    timer = FitTimer()
    require_linear_loss(loss, f_scale, "pi", "bounded linear least squares")
    u = np.ascontiguousarray(u, dtype=float)
    y = np.ascontiguousarray(y, dtype=float)
    if u.shape != y.shape or u.ndim != 1 or u.size < 2:
        raise ValueError(f"u and y must be 1-D, of equal length >= 2, got {u.shape}, {y.shape}")
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(y))):
        raise ValueError("u and y must be finite")
    weights = None if weights is None else check_weights(weights, y.size)
    n, n_k, m = structure.n_play, structure.n_creep, structure.n_deadzone
    n_unknowns = n + 2 * n_k + 1 + 2 * m
    if u.size <= n_unknowns:
        raise ValueError(f"a PI fit with {n} plays, {n_k} creep operators and {m} dead zones "
                         f"a side needs more samples than its {n_unknowns} unknowns, got "
                         f"{u.size}")
    d_inv = output_thresholds(y, m) if d_inv is None else np.asarray(d_inv, dtype=float)
    pi.PiParams(w_h=np.ones(n), w_s=np.ones(2 * m + 1), d_s=d_inv)  # validates d_inv
    # A decreasing model is an increasing one of -u (plays and creep operators are odd).
    polarity = 1.0 if np.cov(u, y)[0, 1] >= 0 else -1.0
    x = polarity * u
    plays, creep = kernels.regressors(x, np.full(n, x[0]), np.full(n_k, x[0]),
                                      np.asarray(structure.play_thresholds),
                                      structure.creep_gains)
    # H + K = sum_i V_i (p_i - p_{i+1}) + sum_j (w+_j z_j + w-_j (x - z_j)) with p_0 = x,
    # V_i = W_i - sum_j w-_j and w_K = w+ - w-.
    loading = plays - np.hstack([plays[:, 1:], np.zeros((u.size, 1))])
    centre, ramps = _ramps(y, d_inv)
    a = np.hstack([loading, creep, x[:, None] - creep, np.ones((u.size, 1)), -ramps])
    lower = np.r_[np.full(n, MIN_SLOPE), np.zeros(2 * n_k), -np.inf, np.full(2 * m, MIN_SLOPE)]
    neutral = np.r_[np.ones(n), np.zeros(2 * n_k + 1), np.ones(2 * m)]
    lam = np.sqrt(ridge * u.size)
    if weights is not None:
        root = np.sqrt(weights)
        a, centre = a * root[:, None], centre * root
        lam *= np.sqrt(np.mean(weights))
    a_aug = np.vstack([a, lam * np.eye(a.shape[1])])
    t_aug = np.concatenate([centre, lam * neutral])
    # BLAS threads do not pay on (n x ~30) problems and cost a lot under load.
    with one_blas_thread():
        sol = lsq_linear(a_aug, t_aug, bounds=(lower, np.inf), method="bvls")
    if not np.all(np.isfinite(sol.x)):
        raise FitDivergedError(f"the fit failed: the linear solver returned non-finite "
                               f"weights ({sol.message})")
    try:
        params = params_from_theta(structure, sol.x, d_inv, polarity)
    except ValueError as exc:  # weights beyond the domain where runs stay bounded
        raise FitDivergedError(f"the fit failed: {exc}") from None
    y_fit, _ = pi.simulate(structure, params, u)
    if accept is not None and not accept(params):
        raise FitDivergedError(f"the fit failed: the fitted model was rejected ({accept_reason})")
    r2 = (y_fit - y) ** 2
    sse = float(np.sum(r2))
    return FitResult(structure=structure, params=params, cost=sse,
                     n_evaluations=2, seconds=timer.seconds(),
                     converged=bool(sol.status > 0), message=str(sol.message), n_starts=1,
                     objective=sse if weights is None else float(weights @ r2),
                     weighted=weights is not None)


