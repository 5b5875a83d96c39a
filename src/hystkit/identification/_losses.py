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

__all__ = ["LOSSES", "check_cost", "objective", "require_linear_loss"]

LOSSES = ("linear", "soft_l1", "huber", "cauchy")
"""Costs a fit can minimise: ``linear`` is the SSE (eq. 5.9), the others scipy's robust losses
(``least_squares(loss=...)``)."""


def check_cost(loss: str, f_scale: float) -> None:
    """Raise ValueError unless `loss` is one of `LOSSES` and `f_scale` a positive number."""
    if loss not in LOSSES:
        raise ValueError(f"loss must be one of {', '.join(LOSSES)}, got {loss!r}")
    if not (isinstance(f_scale, (int, float, np.floating)) and np.isfinite(f_scale)
            and f_scale > 0):
        raise ValueError(f"f_scale must be a positive number, got {f_scale!r}")


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
