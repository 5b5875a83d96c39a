"""What a compensator's fit minimises: the losses a family accepts, per-sample weights read
from a column of the recordings, and what the fit report says about them.

The cost is the SSE (eq. 5.9) unless the caller asks for a robust loss (``loss``, ``f_scale``,
:mod:`hystkit.identification._losses`) or per-sample weights; the stored ``cost``, R² and
AIC/BIC stay on the plain SSE, and these notes say so.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import InputError
from ..identification import (
    MAX_WEIGHT,
    FitResult,
    check_cost,
    cost_label,
)
from ..io import Recording, read_other_columns
from ..models import get_family

__all__ = ["check_loss_available", "cost_info", "cost_options", "standard_error_caveat",
           "supported_losses", "weight_column"]


def supported_losses(model: str) -> tuple[str, ...]:
    """The losses model family `model` can fit with: what its capabilities declare
    (:class:`hystkit.models.Capabilities`; the plain SSE only for a family that declares none,
    and for the linear-least-squares families).

    Parameters
    ----------
    model : str
        A registered family name.

    Returns
    -------
    tuple of str
    """
    return tuple(get_family(model).capabilities.losses)


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
        If the cost is not valid, or `loss` is not one the family's capabilities declare
        (one line naming the losses it takes).
    """
    try:
        check_cost(loss, f_scale)
    except ValueError as exc:
        raise InputError(str(exc)) from None
    losses = supported_losses(model)
    if loss not in losses:
        takes = "the plain SSE only" if losses == ("linear",) else "the losses " + ", ".join(
            losses)
        raise InputError(f"model {model!r} fits {takes} (the losses its family declares); "
                         f"the {loss} loss is not available for it")


def cost_options(model: str, loss: str, f_scale: float,
                  fit_options: Mapping[str, Any] | None) -> dict[str, Any]:
    """The fit's cost options (empty for the plain SSE), checked before any work."""
    check_loss_available(model, loss, f_scale)
    clash = {"loss", "f_scale", "weights"} & set(fit_options or {})
    if clash:
        raise ValueError(f"give {', '.join(sorted(clash))} as fit_compensator's own "
                         f"arguments, not in fit_options")
    return {} if loss == "linear" else {"loss": loss, "f_scale": float(f_scale)}


def cost_info(loss: str, f_scale: float, column: str | None,
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


def standard_error_caveat(info: Mapping[str, Any], result: FitResult) -> str | None:
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
