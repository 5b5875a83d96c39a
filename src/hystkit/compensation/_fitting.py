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

import importlib
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import FitDivergedError, HystkitError, InputError
from ..identification import (
    LOSSES,
    MAX_WEIGHT,
    FitResult,
    check_cost,
    cost_label,
    objective,
    require_linear_loss,
)
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
from ._compensator import MODES, Compensator, check_training_data, inverse_is_bounded
from ._conventions import LinearBaseline, prepare_training_data
from ._diagnostics import MIN_SAMPLES_PER_PARAM, bound_flags, fit_status, fixed_mask
from ._param_vector import flatten_params, simulate_segments
from ._redundancy import redundancy_notes
from ._training_checks import MIN_SAMPLES, check_fitting_data

__all__ = ["MIN_SAMPLES", "check_loss_available", "fit_compensator", "fit_module_constant",
           "supported_losses", "weight_column"]

# The joint polish differentiates numerically, one model run per parameter: above this many
# parameters (Preisach grids) it is skipped and the concatenated fit is kept.
MAX_POLISH_PARAMS = 40
# Residual of a parameter vector outside the family's domain (the polish has no bounds).
_OUTSIDE = 1e3


def fit_module_constant(model: str, name: str, default: Any) -> Any:
    """A constant the fit module of family `model` declares (``hystkit.models.<family>.fit``),
    or `default` where it declares none.

    Parameters
    ----------
    model : str
        A registered family name.
    name : str
        The constant's name, e.g. ``SUPPORTED_LOSSES`` or ``WEIGHT_SUM_FLOOR``.
    default : object
        The value for a family without it (or without a fit module of its own).

    Returns
    -------
    object
    """
    package = type(get_family(model)).__module__.rpartition(".")[0]
    if not package:  # a family object outside a package of its own (a test's stand-in)
        return default
    try:
        fit_module = importlib.import_module(f"{package}.fit")
    except ModuleNotFoundError:
        return default
    return getattr(fit_module, name, default)


def supported_losses(model: str) -> tuple[str, ...]:
    """The losses model family `model` can fit with (all of
    :data:`hystkit.identification.LOSSES` unless its ``fit`` module says otherwise in
    ``SUPPORTED_LOSSES``: the linear-least-squares families fit the SSE only).

    Parameters
    ----------
    model : str
        A registered family name.

    Returns
    -------
    tuple of str
    """
    return tuple(fit_module_constant(model, "SUPPORTED_LOSSES", LOSSES))


def weight_column(recordings: Sequence[Recording], column: str,
                  other_columns: Sequence[Mapping[str, np.ndarray]] | None = None
                  ) -> np.ndarray:
    """Per-sample weights: column `column` of each recording, end to end.

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings, in fitting order.
    column : str
        The weights column's name in their files.
    other_columns : sequence of mappings, optional
        Each recording's columns other than time, position and sensor (as
        :func:`hystkit.io.read_other_columns` returns them); default: read from each
        recording's ``source`` file with the default read options.

    Returns
    -------
    numpy.ndarray, shape (sum of samples,)
        The weights, finite, in ``[0, MAX_WEIGHT]`` (1e100), not all zero.

    Raises
    ------
    InputError
        A recording without the column (naming the file and its other columns), a value that
        is not a finite number in ``[0, MAX_WEIGHT]`` (naming file, column and row), or all
        weights zero.
    """
    from ..io import read_other_columns

    if other_columns is not None and len(other_columns) != len(recordings):
        raise ValueError(f"other_columns must have one mapping per recording "
                         f"({len(recordings)}), got {len(other_columns)}")
    parts = []
    for i, rec in enumerate(recordings):
        if other_columns is not None:
            columns = other_columns[i]
        else:
            try:
                columns = read_other_columns(rec.source, rec.n_samples)
            except (OSError, ValueError) as exc:
                raise InputError(f"{rec.source}: cannot read the weights column {column!r} "
                                 f"({exc})") from None
        if column not in columns:
            others = ", ".join(map(repr, columns)) or "none"
            raise InputError(f"{rec.source}: no weights column {column!r} (its other columns: "
                             f"{others})")
        values = np.asarray(columns[column])
        if values.shape != (rec.n_samples,):
            raise InputError(f"{rec.source}: column {column!r} has {values.size} rows, the "
                             f"recording {rec.n_samples}")
        if values.dtype.kind not in "fiu":
            numbers = _as_numbers(values)
            bad = np.flatnonzero(np.isnan(numbers))
            if bad.size:
                raise InputError(f"{rec.source}: column {column!r}, row {bad[0] + 1}: weight "
                                 f"{str(values[bad[0]])[:40]!r} is not a number")
            values = numbers
        values = values.astype(float)
        bad = np.flatnonzero(~(np.isfinite(values) & (values >= 0)))
        if bad.size:
            raise InputError(f"{rec.source}: column {column!r}, row {bad[0] + 1}: weight "
                             f"{values[bad[0]]:g} is not a finite number >= 0")
        bad = np.flatnonzero(values > MAX_WEIGHT)
        if bad.size:
            raise InputError(f"{rec.source}: column {column!r}, row {bad[0] + 1}: weight "
                             f"{values[bad[0]]:g} is above {MAX_WEIGHT:g} (only the ratios of "
                             f"the weights matter: scale the column down)")
        parts.append(values)
    weights = np.concatenate(parts)
    if not np.any(weights > 0):
        raise InputError(f"{', '.join(r.source for r in recordings)}: every value of the "
                         f"weights column {column!r} is 0")
    return weights


def _as_numbers(values: np.ndarray) -> np.ndarray:
    """Text cells as floats, NaN where a cell is not a number (or empty)."""
    out = np.full(values.size, np.nan)
    for i, cell in enumerate(values):
        try:
            out[i] = float(cell)
        except (TypeError, ValueError):
            pass
    return out


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

    from scipy.optimize import least_squares  # here: only multi-recording fits pay its import

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
        fit by linear least squares take "linear" only (:func:`supported_losses`).
    f_scale : float
        Residual scale of a robust loss, in normalised units (the data are scaled to
        max |.| = 1 before the fit, eq. 5.10).
    weights : str, optional
        Name of a column of the recordings' files holding one weight per sample (finite,
        ``>= 0``; zero drops a sample from the cost), see :func:`weight_column`.
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
    cost_options = _cost_options(model, loss, f_scale, fit_options)
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
        cost_options["weights"] = sample_weights
    result = _fit_family(family, structure, mode, s, p, recs[0].source,
                         {**(fit_options or {}), **cost_options})
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
    info.update(_cost_info(loss, f_scale, weights, sample_weights))
    caveat = _standard_error_caveat(info, result)
    if info.get("standard_errors") and caveat:
        info["standard_errors"]["caveat"] = caveat
    object.__setattr__(comp, "fit_info", info)
    return comp


def check_loss_available(model: str, loss: str, f_scale: float) -> None:
    """Refuse, before any work, a cost the family cannot fit with.

    Parameters
    ----------
    model : str
        A registered family name.
    loss, f_scale
        The requested cost (:func:`hystkit.identification.check_cost`).

    Raises
    ------
    InputError
        If the cost is not valid, or the family fits by linear least squares and `loss` is
        a robust loss (:func:`hystkit.identification.require_linear_loss`, one line).
    """
    try:
        check_cost(loss, f_scale)
    except ValueError as exc:
        raise InputError(str(exc)) from None
    if loss not in supported_losses(model):
        require_linear_loss(loss, f_scale, model, "linear least squares")


def _cost_options(model: str, loss: str, f_scale: float,
                  fit_options: Mapping[str, Any] | None) -> dict[str, Any]:
    """The fit's cost options (empty for the plain SSE), checked before any work."""
    check_loss_available(model, loss, f_scale)
    clash = {"loss", "f_scale", "weights"} & set(fit_options or {})
    if clash:
        raise ValueError(f"give {', '.join(sorted(clash))} as fit_compensator's own "
                         f"arguments, not in fit_options")
    return {} if loss == "linear" else {"loss": loss, "f_scale": float(f_scale)}


def _cost_info(loss: str, f_scale: float, column: str | None,
               weights: np.ndarray | None) -> dict[str, Any]:
    """What the fit minimised, for ``fit_info``: the loss, its scale, the weights column and
    the label of the ``objective`` (the plain SSE's ``cost`` is stored beside it)."""
    plain = loss == "linear" and weights is None
    label = cost_label(loss, f_scale, None if weights is None else f"column {column!r}")
    out = {"loss": loss, "f_scale": float(f_scale) if loss != "linear" else None,
           "weights": column, "objective_label": label}
    if not plain:
        out["criteria_note"] = (f"R², AIC and BIC are on the plain SSE; the fit minimised the "
                                f"{label}")
    return out


def _standard_error_caveat(info: Mapping[str, Any], result: FitResult) -> str | None:
    """Why the Gauss-Newton standard errors (of the plain SSE) are indicative only at this
    optimum, or None where they apply: the fit minimised another cost, or it stopped on an
    active constraint, where the SSE is not stationary."""
    reason = None
    if info.get("criteria_note") is not None:
        reason = f"the fit minimised the {info['objective_label']}"
    elif result.constraint is not None:
        reason = (f"the fit ended on its active constraint {result.constraint}, where the SSE "
                  f"is not stationary")
    return None if reason is None else (f"standard errors of the plain SSE at these "
                                        f"parameters, indicative only: {reason}")


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
