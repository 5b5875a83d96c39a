"""Fit a compensator on one or several recordings, with its fit-time guards.

Several recordings are fitted jointly: each is centred by its own tare / tracker, and each runs
from its own rest state. The family fits the concatenated data (its fit takes one sequence);
then a generic least-squares polish over the family's float parameters (``to_dict``) fits the
per-recording simulations, so the joins between recordings carry no state.

The cost is the SSE (eq. 5.9) unless the caller asks for a robust loss (``loss``, ``f_scale``,
:mod:`hystkit.identification._losses`) or per-sample weights (a column of the recordings):
the family's fit and the joint polish then minimise that cost, while the stored ``cost``,
R² and AIC/BIC stay on the plain SSE.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from .._blas import one_blas_thread
from ..errors import FitDivergedError, HystkitError, InputError
from ..identification import FitResult, objective
from ..io import Recording
from ..metrics import r2
from ..models import Family, get_family
from ._centring import (
    CENTERS,
    DEFAULT_CENTER,
    DEFAULT_TARE_SECONDS,
    DEFAULT_TRACK_SECONDS,
)
from ._chunked_errors import chunked_standard_errors
from ._compensator import MODES, Compensator
from ._conventions import LinearBaseline, prepare_training_data
from ._diagnostics import MIN_SAMPLES_PER_PARAM, bound_flags, fit_status, fixed_mask
from ._fit_costs import (
    cost_info,
    cost_options,
    standard_error_caveat,
    weight_column,
)
from ._fit_info import FitInfo
from ._param_vector import flatten_params, simulate_segments
from ._redundancy import redundancy_notes
from ._training_checks import MIN_SAMPLES, check_fitting_data, check_training_data

__all__ = ["MIN_SAMPLES", "fit_compensator"]

# The joint polish differentiates numerically, one model run per parameter: above this many
# parameters (Preisach grids) it is skipped and the concatenated fit is kept.
MAX_POLISH_PARAMS = 40
# Residual of a parameter vector outside the family's domain (the polish has no bounds).
_OUTSIDE = 1e3


def _polish_jointly(run: Callable, structure: Any, params: Any, inputs: list[np.ndarray],
                    targets: list[np.ndarray], fixed: np.ndarray, loss: str = "linear",
                    f_scale: float = 1.0, weights: np.ndarray | None = None
                    ) -> tuple[Any, str]:
    """Refit the float parameters on per-recording simulations (generic, finite differences);
    those in ``fixed`` (the family fit's gauge, :func:`~._diagnostics.fixed_mask`) stay. The
    cost is the fit's: `loss` with `f_scale`, residuals scaled by ``sqrt(weights)``."""
    theta_all, rebuild = flatten_params(params)
    free = ~fixed
    theta0 = theta_all[free]
    if theta0.size > MAX_POLISH_PARAMS:
        return params, (f"{theta0.size} parameters: fitted on the concatenated recordings, "
                        f"joint polish skipped (more than {MAX_POLISH_PARAMS})")
    target = np.concatenate(targets)
    root = None if weights is None else np.sqrt(weights)

    def full(theta: np.ndarray) -> Any:
        vector = theta_all.copy()
        vector[free] = theta
        return rebuild(vector)

    def residual(theta: np.ndarray) -> np.ndarray:
        try:
            r = simulate_segments(run, structure, full(theta), inputs) - target
        except (ValueError, HystkitError):
            return np.full(target.size, _OUTSIDE)
        r = r if np.all(np.isfinite(r)) else np.full(target.size, _OUTSIDE)
        return r if root is None else root * r

    # here: only multi-recording fits pay its import (~0.9 s cold, the whole of a warm fit)
    from scipy.optimize import least_squares

    # one BLAS thread, as the family fits: trf's SVD of the tall, narrow Jacobian (16000 x 9)
    # took 19.6 ms on OpenBLAS's two threads against 2.0 ms on one, on a busy 2-core machine
    with one_blas_thread():
        sol = least_squares(residual, theta0, method="trf", x_scale="jac", loss=loss,
                            f_scale=f_scale, max_nfev=100)
    start_cost = 0.5 * objective(residual(theta0), loss, f_scale)
    if sol.cost < start_cost:
        return full(sol.x), f"joint polish over {len(inputs)} recordings: {sol.message}"
    return params, "joint polish found nothing better than the concatenated fit"


def _count_params(params: Any, fixed: np.ndarray) -> int:
    """Fitted numbers: the float entries (integers in a params dict are structural) that the
    family's fit does not hold fixed."""
    return int(flatten_params(params)[0].size - np.count_nonzero(fixed))


def fit_compensator(recordings: Recording | Sequence[Recording], size: int | None = None, *,
                    model: str = "mpl", mode: str = "direct", center: str = DEFAULT_CENTER,
                    tare_seconds: float = DEFAULT_TARE_SECONDS,
                    track_seconds: float = DEFAULT_TRACK_SECONDS, diagnose: bool = True,
                    fit_options: Mapping[str, Any] | None = None, loss: str = "linear",
                    f_scale: float = 1.0, weights: str | None = None,
                    other_columns: Sequence[Mapping[str, np.ndarray]] | None = None,
                    **structure_options: Any) -> Compensator:
    """Fit a compensator and its straight-line baseline on one or several recordings.

    Parameters
    ----------
    recordings : Recording or sequence of Recording
        Fitting recordings with ``time`` [s], ``position`` [mm] and ``sensor``, one rate.
    size : int, optional
        The family's size knob (mPL: cells N, 3N + 2 parameters); default per family.
    model : str
        Registered model family (``hystkit.models.FAMILIES``).
    mode : {"direct", "inverse"}
    center : {"fit", "tare", "track", "recording", "none"}
        Where the sensor's offset comes from. Deployable (from the sensor up to each sample
        and the model file): ``fit`` the training recording's offsets, ``tare`` the sensor
        level over the first `tare_seconds` of every recording (the device at rest), ``track``
        a causal low-pass of time constant `track_seconds` that follows slow drift. Oracle:
        ``recording``, the whole recording's mean (the document's protocol; not available in
        use). ``none``: no offsets. The measurements behind the default: the how-to page
        "Centring".
    tare_seconds, track_seconds : float
        Tare window and drift-tracker time constant [s], stored in the model.
    diagnose : bool
        Compute parameter standard errors (one model run per parameter).
    fit_options : mapping, optional
        Keyword options of the family's fit (``Family.fit``), e.g. mPL's ``starts``.
    loss : {"linear", "soft_l1", "huber", "cauchy"}
        The cost the fit (and the joint polish) minimises: "linear" is the SSE (eq. 5.9);
        the robust losses are scipy's (:mod:`hystkit.identification._losses`). Families that
        fit by linear least squares take "linear" only (:func:`._fit_costs.supported_losses`).
    f_scale : float
        Residual scale of a robust loss, in normalised units (the data are scaled to
        max |.| = 1 before the fit, eq. 5.10).
    weights : str, optional
        Name of a column of the recordings' files holding one weight per sample (finite,
        ``>= 0``; zero drops a sample from the cost), see :func:`._fit_costs.weight_column`.
    other_columns : sequence of mappings, optional
        Each recording's other columns, where `weights` is looked up; default: read from
        the recordings' files.
    **structure_options
        Passed to the family's ``make_structure`` (mPL: ``slope_cap``).

    Returns
    -------
    Compensator
        The fitted compensator. The fit's ``status`` in ``fit_info`` is ``ok`` only if the
        model is not constant, beats the straight line on the training data, has no parameter
        on a bound and converged. ``fit_info`` records ``loss``, ``f_scale``, ``weights``
        (the column) and the minimised ``objective`` with its ``objective_label``; its
        ``cost``, R² and AIC/BIC are on the plain SSE. Its ``standard_errors`` (of the plain
        SSE) carry a ``caveat`` where they are indicative only: a robust loss, weights, or an
        active weight-sum constraint.
    """
    recs = [recordings] if isinstance(recordings, Recording) else list(recordings)
    if not recs:
        raise InputError("no fitting recording given")
    family = get_family(model)
    costs = cost_options(model, loss, f_scale, fit_options)
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}, got {mode!r}")
    if center not in CENTERS:
        raise ValueError(f"center must be one of {CENTERS}, got {center!r}")
    if mode == "inverse" and family.invert is None:
        raise InputError(f"model {model!r} has no inverse ({family.no_inverse_reason}); "
                         f"use --mode direct")
    check_training_data(recs)
    sample_weights = None if weights is None else weight_column(recs, weights, other_columns)
    try:
        structure = family.make_structure(recs[0].dt, family.default_size if size is None
                                          else size, **structure_options)
    except (ValueError, TypeError) as exc:
        raise InputError(f"model {model!r}: {exc}") from None
    # Before any fit: enough samples for the parameters and a signal that moves.
    check_fitting_data(recs, family, structure)
    conventions, s_list, p_list = prepare_training_data(
        recs, center, tare_seconds=tare_seconds, track_seconds=track_seconds)
    s, p = _joined(s_list), _joined(p_list)
    inputs, targets = (s_list, p_list) if mode == "direct" else (p_list, s_list)
    if sample_weights is not None:
        costs["weights"] = sample_weights
    result = _fit_family(family, structure, mode, s, p, recs[0].source,
                         {**(fit_options or {}), **costs})
    params, joint_note = result.params, ""
    fixed = fixed_mask(family, structure, params)
    if len(recs) > 1:
        params, joint_note = _polish_jointly(family.simulate, structure, params, inputs, targets,
                                             fixed, loss, f_scale, sample_weights)
    n_params = _count_params(params, fixed)
    if s.size < MIN_SAMPLES_PER_PARAM * n_params:
        raise InputError(f"{recs[0].source}: column 'position': {s.size} samples for "
                         f"{n_params} parameters of {model}; a fit needs at least "
                         f"{MIN_SAMPLES_PER_PARAM} samples per parameter")
    baseline = LinearBaseline.fit(s, p)
    comp = Compensator(structure=structure, params=params, mode=mode, center=center,
                       baseline=baseline, model=model, tare_seconds=tare_seconds,
                       track_seconds=track_seconds, training_range=(float(s.min()),
                                                                    float(s.max())),
                       position_range=(float(min(r.position.min() for r in recs)),
                                       float(max(r.position.max() for r in recs))),
                       **conventions)
    info = _fit_info(comp, result, recs, s, p, s_list, inputs, targets, diagnose,
                     (loss, f_scale, sample_weights))
    info["n_params"], info["joint_fit"] = n_params, joint_note or None
    info.update(cost_info(loss, f_scale, weights, sample_weights))
    caveat = standard_error_caveat(info, result)
    if info.get("standard_errors") and caveat:
        info["standard_errors"]["caveat"] = caveat
    return replace(comp, fit_info=FitInfo(info))


def _fit_family(family: Family, structure: Any, mode: str, s: np.ndarray,
                p: np.ndarray, source: str, options: dict[str, Any]) -> FitResult:
    """The family's fit; whatever else it raises on data that passed the checks (a solver's
    LinAlgError, a family's ValueError) is that family's failure, said in one line."""
    try:
        return _run_fit(family, structure, mode, s, p, options)
    except HystkitError:
        raise
    # A numerical failure of the family's fit is reported; a programming error is not hidden.
    except (ValueError, TypeError, ArithmeticError, IndexError, np.linalg.LinAlgError) as exc:
        raise FitDivergedError(f"{source}: the {family.name} fit failed on these data "
                               f"({type(exc).__name__}: {exc})") from exc


def _run_fit(family: Family, structure: Any, mode: str, s: np.ndarray,
             p: np.ndarray, options: dict[str, Any]) -> FitResult:
    if mode == "direct":
        return family.fit(s, p, structure, **options)
    # The exact inverse of a discrete forward model can be unstable even when the model is
    # not (for the mPL its cells see a self-gain 1 + w_k / w_0); only keep fits whose inverse
    # stays bounded on the training data.
    return family.fit(p, s, structure, accept=lambda params: inverse_is_bounded(
        family, structure, params, s), accept_reason="their inverse diverges on the training "
                                                     "data; use --mode direct or a smaller model",
                      **options)


def inverse_is_bounded(family: Any, structure: Any, params: Any, s: np.ndarray) -> bool:
    """Whether a candidate's inverse stays bounded on normalised training data."""
    try:
        p_hat, _ = family.invert(structure, params, s)
    except FitDivergedError:
        return False
    return bool(np.max(np.abs(p_hat)) < 10.0)  # normalised data: |p| <= 1 when it works


def _joined(columns: list[np.ndarray]) -> np.ndarray:
    """The recordings' columns end to end (one recording: itself, not a copy)."""
    return columns[0] if len(columns) == 1 else np.concatenate(columns)


def _fit_info(comp: Compensator, result: FitResult, recs: Sequence[Recording], s: np.ndarray,
              p: np.ndarray, s_list: list[np.ndarray], inputs: list[np.ndarray],
              targets: list[np.ndarray], diagnose: bool,
              cost: tuple[str, float, np.ndarray | None] = ("linear", 1.0, None)) -> dict:
    """The solver's report plus the guards: status, training R², bounds, AIC/BIC, SEs, and
    the ``objective`` (`cost`: loss, f_scale, weights) beside the plain SSE.

    ``s``, ``p``: normalised sensor and position of all recordings end to end. Full-length
    arrays are made only where needed (estimate, straight line); the rest is in place.
    """
    family, structure = comp.family, comp.structure
    run = family.simulate if comp.mode == "direct" else family.invert
    estimate = simulate_segments(run, structure, comp.params, s_list)
    line = comp.baseline(s)
    # after a joint polish (no bounds) the family fit's optimum is not the model's
    on_bounds, limit_notes = bound_flags(result) if len(recs) == 1 else (None, [])
    status, message = fit_status(estimate, p, line, on_bounds, result.converged,
                                 limited=getattr(structure, "limit", True))
    r2_model, r2_line = r2(p, estimate), r2(p, line)
    del line
    # The forward model's misfit; in direct mode the estimate is that forward run.
    residual = estimate if comp.mode == "direct" else simulate_segments(
        family.simulate, structure, comp.params, inputs)
    residual -= _joined(targets)
    sse = float(residual @ residual)
    minimised = objective(residual, *cost)
    del estimate, residual
    n = p.size
    k = _count_params(comp.params, fixed_mask(family, structure, comp.params))
    log_term = n * np.log(max(sse, 1e-300) / n)
    info = {"cost": sse, "objective": minimised, "fit_seconds": result.seconds,
            "n_evaluations": result.n_evaluations,
            "converged": result.converged, "message": result.message,
            "n_starts": result.n_starts, "training_source": recs[0].source,
            "training_sources": [r.source for r in recs],
            "training_samples": int(n), "status": status, "status_message": message,
            "training_r2": r2_model, "training_linear_r2": r2_line,
            "on_bounds": on_bounds, "at_model_limits": limit_notes,
            "aic": float(log_term + 2 * k),
            "bic": float(log_term + k * np.log(n))}
    if diagnose:
        info["standard_errors"] = chunked_standard_errors(family, structure, comp.params,
                                                          inputs, targets)
        info["redundant"] = redundancy_notes(family, structure, comp.params, inputs, targets,
                                             sse)
    return info
