"""Recursive least squares with exponential forgetting, as pure functions of an explicit state.

After ``n`` updates with regressors ``phi_k`` and targets ``r_k`` from the prior ``theta_0``,
``P_0``, the state holds the minimiser of the exponentially weighted least-squares cost

    J(theta) = sum_k lam^(n-k) (r_k - phi_k' theta)^2
               + lam^n (theta - theta_0)' P_0^-1 (theta - theta_0)

and ``P_n`` is the inverse of its normal matrix (up to rounding: the recursion is the
Sherman-Morrison form of that normal equation). ``lam = 1`` is ordinary least squares with a
Gaussian prior; ``lam < 1`` forgets old samples with a memory of about ``1 / (1 - lam)`` updates,
so the estimate can follow slowly drifting parameters.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["RlsState", "rls_bound", "rls_start", "rls_update"]


@dataclass(frozen=True, eq=False)
class RlsState:
    """Estimate, its covariance factor and the number of updates so far.

    Parameters
    ----------
    theta : array, shape (p,)
        Present parameter estimate.
    cov : array, shape (p, p)
        ``P``: the inverse of the weighted normal matrix (symmetric, positive definite).
    n_updates : int, default 0
        Samples absorbed since the prior.
    """

    theta: np.ndarray
    cov: np.ndarray
    n_updates: int = 0

    def __post_init__(self) -> None:
        for name in ("theta", "cov"):
            value = np.array(getattr(self, name), dtype=np.float64)
            value.flags.writeable = False
            object.__setattr__(self, name, value)


def rls_start(theta0: np.ndarray, prior_std: np.ndarray) -> RlsState:
    """The state before any sample: ``theta0`` with independent prior standard deviations.

    Parameters
    ----------
    theta0 : array, shape (p,)
        Prior estimate.
    prior_std : array, shape (p,)
        Standard deviation of each parameter's prior (> 0): ``P_0 = diag(prior_std**2)``.

    Returns
    -------
    RlsState
        ``theta0``, ``P_0`` and no updates.

    Raises
    ------
    ValueError
        If ``prior_std`` is not ``p`` finite positive numbers.
    """
    theta0 = np.asarray(theta0, dtype=np.float64)
    std = np.asarray(prior_std, dtype=np.float64)
    if std.shape != theta0.shape or not np.all(std > 0) or not np.all(np.isfinite(std)):
        raise ValueError(f"prior_std must be {theta0.size} finite positive numbers, got {std}")
    return RlsState(theta0, np.diag(std * std))


def rls_update(state: RlsState, phi: np.ndarray, r: float, forgetting: float) -> RlsState:
    """Absorb one sample ``r = phi' theta + noise`` with forgetting factor ``forgetting``.

    The standard recursion (gain ``k``, a-priori error ``e``)::

        k = P phi / (lam + phi' P phi),  theta += k e,  e = r - phi' theta,
        P = (P - k phi' P) / lam

    ``P`` is made symmetric again after each update, so rounding cannot make it drift into an
    asymmetric (and eventually indefinite) matrix over a long stream.

    Parameters
    ----------
    state : RlsState
        The state before the sample.
    phi : array, shape (p,)
        The sample's regressor.
    r : float
        The sample's target.
    forgetting : float
        Forgetting factor ``lam`` in (0, 1] (1: never forgets).

    Returns
    -------
    RlsState
        The state after the sample.
    """
    phi = np.asarray(phi, dtype=np.float64)
    p_phi = state.cov @ phi
    gain = p_phi / (forgetting + phi @ p_phi)
    error = r - phi @ state.theta
    cov = (state.cov - np.outer(gain, p_phi)) / forgetting
    return RlsState(state.theta + gain * error, 0.5 * (cov + cov.T), state.n_updates + 1)


def rls_bound(state: RlsState, max_trace: float) -> RlsState:
    """``state`` with ``P`` scaled down to trace ``max_trace`` if it is larger (else unchanged).

    With ``lam < 1`` and samples that excite only some directions (a device resting at one
    position gives the same regressor again and again), ``P`` grows as ``lam^-n`` along the
    others ("covariance wind-up"); the next different sample would then move ``theta`` by an
    amount set by noise. Bounding ``P`` by the prior's trace keeps the gain no larger than it
    was at the start.

    Parameters
    ----------
    state : RlsState
        Any state.
    max_trace : float
        Largest trace allowed for ``P``.

    Returns
    -------
    RlsState
        ``state`` itself if the trace of ``P`` is at most ``max_trace``, else a copy with ``P``
        scaled to that trace.
    """
    trace = float(np.trace(state.cov))
    if trace <= max_trace:
        return state
    return RlsState(state.theta, state.cov * (max_trace / trace), state.n_updates)
