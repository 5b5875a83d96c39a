"""Fit-time guards: is a fitted compensator worth more than its straight line?

A least-squares solver reports "converged" for a model that collapsed to a constant, for one
whose parameters sit on their bounds and for one worse than a straight line. These checks look
at the fitted model itself, for any family, and give the fit a ``status`` that says so.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..identification import FitResult
from ..metrics import r2
from ..models import Family
from ._param_vector import flatten_params, named_floats
from ._verdict import verdict

__all__ = ["BOUND_TOLERANCE", "COLLAPSE_RATIO", "MIN_SAMPLES_PER_PARAM", "bound_flags",
           "error_steps", "errors_from_factor", "fit_status", "fixed_mask", "parameter_names",
           "standard_errors", "step_within_domain"]

# A fit needs at least this many samples per fitted number (with fewer, the residual has too
# few degrees of freedom for the noise level, hence for standard errors).
MIN_SAMPLES_PER_PARAM = 2
# An estimate whose standard deviation is below this share of the target's is a constant.
COLLAPSE_RATIO = 1e-3
# A parameter within this share of its bound interval of a bound is "on the bound".
BOUND_TOLERANCE = 1e-4


def step_within_domain(rebuild: Callable[[np.ndarray], Any], theta: np.ndarray,
                       e: np.ndarray, h: float) -> tuple[Any, float]:
    """A finite-difference step that stays in the family's domain.

    Parameters
    ----------
    rebuild : callable
        Parameter vector -> the family's parameters (raises ValueError outside the domain).
    theta : numpy.ndarray
        The fitted parameter vector.
    e : numpy.ndarray
        The unit vector of the parameter to move.
    h : float
        The step.

    Returns
    -------
    params : object or None
        The parameters moved by ``+h`` along `e` (a forward difference), else by ``-h`` (a
        backward one) where the forward step leaves the domain (two PI dead-zone thresholds
        4e-7 apart swap order); None if both do: that Jacobian column is zero and the
        parameter is reported as not determined.
    step : float
        The signed step taken.
    """
    for step in (h, -h):
        try:
            return rebuild(theta + step * e), step
        except ValueError:
            continue
    return None, h


def standard_errors(residual: Callable[[np.ndarray], np.ndarray], params: Any,
                    n_data: int, fixed: np.ndarray | None = None) -> dict:
    """Standard errors of the float parameters from a finite-difference Jacobian at the optimum.

    ``residual(params)`` is the model-minus-target vector of the fit; the covariance is
    ``s^2 (J^T J)^-1`` with ``s^2 = SSE / (n - p)`` (Gauss-Newton), ``p`` the free parameters.
    Parameters the data do not determine (``J^T J`` numerically singular) get ``inf``; those
    in ``fixed`` (see :func:`fixed_mask`) are not differentiated.

    Returns
    -------
    dict
        ``values`` and ``standard_errors`` (flat, the order of ``params.to_dict()``'s float
        entries; None where undetermined or fixed), ``relative`` (SE / |value|),
        ``condition_number`` of ``J^T J`` over the free parameters, ``fixed`` (the names of
        the parameters the fit holds fixed).
    """
    theta, rebuild = flatten_params(params)
    free = _free(theta, fixed)
    r0 = residual(rebuild(theta))
    steps = error_steps(theta)
    jac = np.empty((r0.size, int(free.sum())))
    for col, j in enumerate(np.flatnonzero(free)):
        moved, step = step_within_domain(rebuild, theta, np.eye(theta.size)[j], steps[j])
        jac[:, col] = 0.0 if moved is None else (residual(moved) - r0) / step
    return errors_from_factor(theta, jac, float(r0 @ r0), n_data, free, parameter_names(params))


def parameter_names(params: Any) -> list[str]:
    """Names of the float entries of ``params.to_dict()`` in :func:`flatten_params` order
    (depth first: ``w[1]``, ``v_b``; nested lists ``a[0][2]``)."""
    return [name for name, _ in named_floats(params.to_dict())]


def fixed_mask(family: Family, structure: Any, params: Any) -> np.ndarray:
    """Which float entries of ``params`` (:func:`flatten_params` order) the family's fit holds
    fixed (:meth:`hystkit.models.Family.fixed_params`), as a boolean array; the hook is
    optional, so a family object without it (a duck-typed stand-in) holds none fixed."""
    names = parameter_names(params)
    declared = getattr(family, "fixed_params", None)
    fixed = set() if declared is None else set(declared(structure, params))
    if unknown := fixed.difference(names):
        raise ValueError(f"{family.name}.fixed_params names {sorted(unknown)}, which are not "
                         f"float entries of its parameters")
    return np.array([name in fixed for name in names], dtype=bool)


def _free(theta: np.ndarray, fixed: np.ndarray | None) -> np.ndarray:
    return np.ones(theta.size, bool) if fixed is None else ~np.asarray(fixed, bool)


def error_steps(theta: np.ndarray) -> np.ndarray:
    """Forward-difference steps of the standard errors' Jacobian (relative, floor 1e-9)."""
    return 1e-6 * np.maximum(np.abs(theta), 1e-3)


def errors_from_factor(theta: np.ndarray, factor: np.ndarray, sse: float, n_data: int,
                       free: np.ndarray | None = None, names: list[str] | None = None) -> dict:
    """:func:`standard_errors`' result from any ``factor`` with ``factor^T factor = J^T J``.

    ``factor`` is the Jacobian itself or its triangular factor ``R`` (``J = Q R``): both have
    the same singular values and right singular vectors, so the chunked route
    (:mod:`._chunked_errors`) gives the dense one's numbers without holding ``J``. Its columns
    are the ``free`` parameters (default: all); the others are held fixed by the fit and get
    no standard error. ``names`` (:func:`parameter_names`; default ``theta[i]``) name them.
    """
    free = np.ones(theta.size, bool) if free is None else np.asarray(free, bool)
    dof = max(n_data - int(free.sum()), 1)
    sigma2 = sse / dof
    _u, sv, vt = np.linalg.svd(factor, full_matrices=False)
    determined = sv > sv[0] * 1e-8 if sv.size and sv[0] > 0 else np.zeros(sv.size, bool)
    inv_sv2 = np.where(determined, 1.0 / np.where(determined, sv, 1.0) ** 2, 0.0)
    variance = sigma2 * np.einsum("kj,k,kj->j", vt, inv_sv2, vt)
    # A parameter with weight in an undetermined direction has no finite standard error.
    blind = np.abs(vt[~determined]).max(axis=0) > 1e-6 if (~determined).any() \
        else np.zeros(vt.shape[1], bool)
    se = np.full(theta.size, np.inf)
    se[free] = np.where(blind, np.inf, np.sqrt(np.maximum(variance, 0.0)))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(theta != 0, se / np.abs(theta), np.inf)
    cond = float((sv[0] / sv[-1]) ** 2) if sv.size and sv[-1] > 0 else float("inf")
    names = names or [f"theta[{i}]" for i in range(theta.size)]
    fixed = [name for name, f in zip(names, free, strict=True) if not f]
    return {"values": theta.tolist(), "standard_errors": _finite_or_none(se),
            "relative": _finite_or_none(rel), "condition_number": _finite_or_none(cond),
            "fixed": fixed}


def _finite_or_none(x):
    """JSON has no inf: an undetermined standard error is written as null."""
    if np.ndim(x) == 0:
        return float(x) if np.isfinite(x) else None
    return [float(v) if np.isfinite(v) else None for v in np.asarray(x)]


def bound_flags(result: FitResult) -> tuple[list[str] | None, list[str]]:
    """Parameters on or near a bound: ``(search box hits, model-limit notes)``.

    The first list names (``FitResult.names``, else ``theta[i]``) the optimiser coordinates
    on a bound of the search box, with the side, e.g. ``"log_v_t[2] (upper)"``; None when the
    fit did not record its bounds. The second holds the family's notes for coordinates on a
    bound that is a limit of the model itself (``"cell 2 runs at the Euler slope cap ..."``):
    a fitted model there is valid, so these are notes, not a failed guard.
    """
    find = getattr(result, "bound_hits", None)
    hits = None if find is None else find(BOUND_TOLERANCE)
    if hits is None:
        return None, []
    return ([f"{h.name} ({h.side})" for h in hits if h.limit is None],
            [h.limit for h in hits if h.limit is not None])


def fit_status(estimate: np.ndarray, target: np.ndarray, line: np.ndarray,
               on_bounds: list[str] | None, converged: bool,
               limited: bool = True) -> tuple[str, str]:
    """``(status, message)`` of a fit from its training estimate and the straight line's.

    Status is the first that applies: ``collapsed`` (estimate constant), ``no_signal``,
    ``worse_than_line`` or ``poor`` (the shared verdict on the training data,
    :func:`~._verdict.verdict`: a model that cannot follow its own training data well enough
    to be used),
    ``on_bounds`` (search box hits, by name: see :func:`bound_flags`; a model at its own limit
    is not on bounds), ``not_converged``, ``no_limit`` (a model without the stability limit,
    ``limited`` False: fitted for study, it may diverge on other data), else ``ok``.
    """
    r2_model = r2(target, estimate)
    if np.std(estimate) < COLLAPSE_RATIO * np.std(target):
        return "collapsed", (f"the fitted model is constant (std of its estimate "
                             f"{np.std(estimate):.3g} against {np.std(target):.3g} of the target)")
    status, message = verdict(r2_model, r2(target, line), "training")
    if status != "ok":
        return status, message
    if on_bounds:
        return "on_bounds", (f"{len(on_bounds)} parameter(s) on a bound of the search box: "
                             f"{', '.join(map(str, on_bounds))}")
    if not converged:
        return "not_converged", "the solver stopped on its evaluation budget"
    if not limited:
        return "no_limit", (f"fitted without the stability limit (eq. 5.29, --no-limit; "
                            f"training R² {r2_model:.4f}): its Euler step can diverge on other "
                            f"data (sec. 5.3.3)")
    return "ok", message
