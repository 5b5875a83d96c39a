"""Is there anything to fit? Checks of fitting data that run before any family does.

A least-squares solver "converges" on two samples (SSE 1e-31) and on a constant signal (a
collapsed model); some families crash on them instead. These checks refuse such data for every
family alike, with one message naming the file and column: too few samples for the model's
parameters, a column that does not vary (or varies below float resolution on a huge offset), a
column that leaves its resting level for only a few samples (a spike).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import InputError
from ..io import Recording
from ..models import Family
from ._diagnostics import MIN_SAMPLES_PER_PARAM
from ._param_vector import flatten_params

__all__ = ["MIN_MOVING_SAMPLES", "MIN_SAMPLES", "RESOLUTION", "check_excursion",
           "check_fitting_data", "check_sample_count", "check_training_data", "count_fitted"]

# Fewer samples than this cannot describe a loop at all, whatever the model.
MIN_SAMPLES = 20
# A column varying by less than this share of its magnitude is constant to float64 once its
# offset is removed (1e-12 leaves under 4 significant digits of the variation).
RESOLUTION = 1e-12
# A column must leave its resting level (median, +- 1 % of its range) in at least this many
# samples: a single spike or glitch is not an excursion a model can be fitted to.
MIN_MOVING_SAMPLES = MIN_SAMPLES
_REST_BAND = 0.01


def check_fitting_data(recordings: Sequence[Recording], family: Family | None = None,
                       structure: Any = None) -> None:
    """Every check of this module, before any fit: enough samples (per parameter of `family`
    at `structure` when given) and a position and sensor that move.

    Parameters
    ----------
    recordings : sequence of Recording
        Fitting recordings.
    family : Family, optional
        The family to be fitted; without it only a general minimum of samples is required.
    structure : object, optional
        The family's structure, whose parameter count sets the samples needed.

    Raises
    ------
    InputError
        Naming the (first) file, the column and what is missing.
    """
    n_params = None if family is None else count_fitted(family, structure)
    check_sample_count(recordings, n_params, "" if family is None else family.name)
    check_excursion(recordings)


def check_excursion(recordings: Sequence[Recording]) -> None:
    """Refuse a position or sensor column without a usable excursion.

    Parameters
    ----------
    recordings : sequence of Recording
        Fitting recordings.

    Raises
    ------
    InputError
        Naming the (first) file and the column: constant, constant to float resolution (a huge
        offset with a tiny variation), or moving in fewer than ``MIN_MOVING_SAMPLES`` samples.
    """
    source = recordings[0].source
    for column in ("position", "sensor"):
        columns = [getattr(r, column) for r in recordings]
        x = columns[0] if len(columns) == 1 else np.concatenate(columns)
        lo, hi = float(np.min(x)), float(np.max(x))
        span, level = hi - lo, max(abs(lo), abs(hi))
        if span == 0:
            raise InputError(f"{source}: column {column!r} is constant ({lo:.6g}); nothing to "
                             f"fit")
        if span <= RESOLUTION * level:
            raise InputError(f"{source}: column {column!r} varies by only {span:.3g} around "
                             f"{level:.3g}, below what float64 resolves once the offset is "
                             f"removed; nothing to fit (subtract the offset before saving)")
        away = np.subtract(x, np.median(x))  # one full-length temporary, worked in place
        moving = int(np.count_nonzero(np.abs(away, out=away) > _REST_BAND * span))
        if moving < MIN_MOVING_SAMPLES:
            raise InputError(f"{source}: column {column!r} leaves its resting level in only "
                             f"{moving} of {x.size} samples (a spike or a glitch, not a "
                             f"motion); a fit needs at least {MIN_MOVING_SAMPLES}")


def count_fitted(family: Family, structure: Any) -> int | None:
    """Fitted numbers of `family` at `structure`, known before fitting (from a draw of its
    documented domain).

    Parameters
    ----------
    family : Family
        The family to be fitted.
    structure : object
        Its structure.

    Returns
    -------
    int or None
        The count of float parameters; None for a family that documents no domain.
    """
    draw = getattr(family, "random_params", None)  # duck-typed stand-ins may lack it
    if draw is None:
        return None
    try:
        params = draw(structure, np.random.default_rng(0))
    except NotImplementedError:
        return None
    return int(flatten_params(params)[0].size)


def check_sample_count(recordings: Sequence[Recording], n_params: int | None, model: str
                       ) -> None:
    """At least ``MIN_SAMPLES`` samples, and ``MIN_SAMPLES_PER_PARAM`` per fitted number.

    Raises
    ------
    InputError
        Naming the (first) file, the sample count and what the model needs.
    """
    n = sum(r.n_samples for r in recordings)
    per_param = MIN_SAMPLES_PER_PARAM * (n_params or 0)
    need = max(MIN_SAMPLES, per_param)
    if n < need:
        per = ("" if per_param < MIN_SAMPLES else f" ({MIN_SAMPLES_PER_PARAM} samples per "
                                                  f"parameter, {model} has {n_params})")
        raise InputError(f"{recordings[0].source}: column 'position': {n} samples; a fit needs "
                         f"at least {need}{per}")


def check_training_data(recordings: Sequence[Recording]) -> None:
    """Every fitting recording needs a position column and the same sampling step."""
    for rec in recordings:
        if not rec.has_position():
            raise InputError(f"{rec.source}: column 'position' is needed to fit")
        if abs(rec.dt - recordings[0].dt) > 0.01 * recordings[0].dt:
            raise InputError(f"{rec.source}: column 'time': sampled every {rec.dt:.6g} s, but "
                             f"{recordings[0].source} every {recordings[0].dt:.6g} s; fit "
                             f"recordings must share one rate")
