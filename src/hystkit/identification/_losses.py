"""The costs a fit can minimise: the SSE (eq. 5.9) and scipy's robust losses, with weights.

A fit's objective is ``sum_i f^2 rho(w_i r_i^2 / f^2)``: residual ``r_i`` scaled by
``sqrt(w_i)`` (per-sample weight), then passed through the loss ``rho`` of
``scipy.optimize.least_squares`` with residual scale ``f`` (``f_scale``):

* ``linear``: ``rho(z) = z``, the (weighted) SSE, whatever ``f``;
* ``soft_l1``: ``rho(z) = 2 (sqrt(1 + z) - 1)``;
* ``huber``: ``rho(z) = z`` for ``z <= 1``, else ``2 sqrt(z) - 1``;
* ``cauchy``: ``rho(z) = ln(1 + z)``.

Residuals much smaller than ``f`` count as in the SSE; larger ones count less (huber, soft_l1:
linearly; cauchy: logarithmically), so a few outlying samples pull the fit less.
"""

from __future__ import annotations

import numpy as np

__all__ = ["LOSSES", "check_cost", "cost_label", "loss_slope", "objective",
           "require_linear_loss", "robust_linear_fit"]

LOSSES = ("linear", "soft_l1", "huber", "cauchy")
"""Costs a fit can minimise: ``linear`` is the SSE (eq. 5.9), the others scipy's robust losses
(``least_squares(loss=...)``)."""


def check_cost(loss: str, f_scale: float) -> None:
    """Raise ValueError unless `loss` is one of `LOSSES` and `f_scale` a positive number.

    Parameters
    ----------
    loss : str
        The loss's name.
    f_scale : float
        Its residual scale.

    Raises
    ------
    ValueError
        Naming the bad value.
    """
    if loss not in LOSSES:
        raise ValueError(f"loss must be one of {', '.join(LOSSES)}, got {loss!r}")
    if not (isinstance(f_scale, (int, float, np.floating)) and np.isfinite(f_scale)
            and f_scale > 0):
        raise ValueError(f"f_scale must be a positive number, got {f_scale!r}")


def cost_label(loss: str, f_scale: float, weights: str | None = None) -> str:
    """What a fit minimised, in words, for messages, reports and ``fit_info``.

    Parameters
    ----------
    loss : str
        One of :data:`LOSSES`.
    f_scale : float
        The robust loss's residual scale (unused by ``"linear"``).
    weights : str, optional
        What weighted the residuals (``"column 'w'"``); None if unweighted.

    Returns
    -------
    str
        ``"SSE"``, ``"SSE weighted by column 'w'"``, ``"huber cost (f_scale 0.05)"`` or
        ``"huber cost (f_scale 0.05, weighted by column 'w')"``.
    """
    if loss == "linear":
        return "SSE" if weights is None else f"SSE weighted by {weights}"
    weighted = "" if weights is None else f", weighted by {weights}"
    return f"{loss} cost (f_scale {f_scale:g}{weighted})"


def objective(residual: np.ndarray, loss: str = "linear", f_scale: float = 1.0,
              weights: np.ndarray | None = None) -> float:
    """``sum_i f^2 rho(w_i r_i^2 / f^2)`` (twice scipy's ``cost``; see the module docstring).

    Parameters
    ----------
    residual : array, shape (m,)
        Model output minus target.
    loss : {"linear", "soft_l1", "huber", "cauchy"}
    f_scale : float
        Residual scale ``f`` of a robust loss.
    weights : array, shape (m,), optional
        Per-residual weights (default all 1).

    Returns
    -------
    float
        The objective; the SSE for ``loss="linear"`` without weights.
    """
    check_cost(loss, f_scale)
    r = np.asarray(residual, dtype=float)
    if loss == "linear":  # as the fits sum it: r @ r
        return float(r @ r) if weights is None else float(np.asarray(weights, float) @ (r * r))
    z = r * r if weights is None else np.asarray(weights, dtype=float) * r * r
    z = z / f_scale ** 2
    if loss == "soft_l1":
        rho = 2.0 * (np.sqrt(1.0 + z) - 1.0)
    elif loss == "huber":
        rho = np.where(z <= 1.0, z, 2.0 * np.sqrt(z) - 1.0)
    else:
        rho = np.log1p(z)
    return float(f_scale ** 2 * np.sum(rho))


def require_linear_loss(loss: str, f_scale: float, model: str, method: str) -> None:
    """Refuse a robust loss for a family whose fit has no iterative cost to put it in.

    Parameters
    ----------
    loss, f_scale
        The requested cost (checked as by :func:`check_cost`).
    model : str
        The family's name, for the message.
    method : str
        How it fits (``"linear least squares"``), for the message.

    Raises
    ------
    InputError
        If `loss` is not ``"linear"``: one line naming the model and its method.
    ValueError
        If `loss` or `f_scale` are not valid at all.
    """
    from ..errors import InputError

    check_cost(loss, f_scale)
    if loss != "linear":
        raise InputError(f"model {model!r} fits by {method}; the {loss} loss is not available "
                         f"for it (its fit takes per-sample weights)")


def loss_slope(z: np.ndarray, loss: str) -> np.ndarray:
    """``rho'(z)`` of scipy's loss `loss`: the IRLS weight of a residual with ``z = w r^2 /
    f^2``.

    Parameters
    ----------
    z : array_like
        Scaled squared residuals, ``>= 0``.
    loss : {"linear", "soft_l1", "huber", "cauchy"}
        The loss.

    Returns
    -------
    numpy.ndarray
        1 (linear), ``(1 + z)^-1/2`` (soft_l1), ``min(1, z^-1/2)`` (huber) or
        ``1 / (1 + z)`` (cauchy).
    """
    z = np.asarray(z, dtype=float)
    if loss == "linear":
        return np.ones_like(z)
    if loss == "soft_l1":
        return 1.0 / np.sqrt(1.0 + z)
    if loss == "huber":
        return np.where(z <= 1.0, 1.0, 1.0 / np.sqrt(np.maximum(z, 1.0)))
    if loss == "cauchy":
        return 1.0 / (1.0 + z)
    raise ValueError(f"loss must be one of {', '.join(LOSSES)}, got {loss!r}")


def robust_linear_fit(a: np.ndarray, b: np.ndarray, loss: str = "linear",
                      f_scale: float = 1.0, weights: np.ndarray | None = None, *,
                      max_iter: int = 100, rtol: float = 1e-10) -> np.ndarray:
    """``argmin_x sum_i f^2 rho(w_i (a x - b)_i^2 / f^2)`` for a linear model, by iteratively
    reweighted least squares from the (weighted) least-squares solution.

    Each step solves ``min sum_i w_i rho'(z_i) (a x - b)_i^2`` with ``rho'`` at the previous
    residuals; its fixed point is a stationary point of the objective (for the non-convex
    cauchy loss, the one nearest the least-squares start).

    Parameters
    ----------
    a : array, shape (m, p)
        Design matrix.
    b : array, shape (m,)
        Target.
    loss, f_scale, weights
        The cost, as in :func:`objective`.
    max_iter : int
        Most reweighting steps.
    rtol : float
        Stop when no coefficient moves more than ``rtol`` times the largest one.

    Returns
    -------
    numpy.ndarray, shape (p,)
        The coefficients (``lstsq``'s minimum-norm solution where ``a`` is rank deficient).
    """
    check_cost(loss, f_scale)
    if weights is None:
        w = np.ones(b.size)
        x = np.linalg.lstsq(a, b, rcond=None)[0]
    else:
        w = np.asarray(weights, dtype=float)
        root = np.sqrt(w)
        x = np.linalg.lstsq(a * root[:, None], b * root, rcond=None)[0]
    if loss == "linear":
        return x
    for _ in range(max_iter):
        r = a @ x - b
        root = np.sqrt(w * loss_slope(w * r * r / f_scale ** 2, loss))
        x_new = np.linalg.lstsq(a * root[:, None], b * root, rcond=None)[0]
        done = np.max(np.abs(x_new - x)) <= rtol * max(float(np.max(np.abs(x_new))), 1e-300)
        x = x_new
        if done:
            break
    return x
