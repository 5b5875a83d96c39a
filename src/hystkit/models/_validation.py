"""Argument checks shared by the model modules.

Every model validates the same kinds of things: parameter arrays (frozen, finite, of a given
size), the signal a run is fed, the initial state of a run, and the sample time and Euler slope
cap of its structure. The functions here raise :class:`ValueError` with the wording the models
have always used, so callers (and tests) see one message for one kind of mistake.
:func:`run_steps` is the readable reference run every model's ``simulate_reference`` shares.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hystkit._kernel_inputs import read_only
from hystkit.errors import FitDivergedError

__all__ = [
    "MAX_VALUE",
    "broadcast_state",
    "check_cells",
    "check_dt",
    "check_finite_run",
    "check_magnitude",
    "check_positive_int",
    "check_range",
    "check_signal",
    "check_size",
    "check_slope_cap",
    "check_structure_size",
    "finite_floats",
    "freeze_arrays",
    "frozen_array",
    "frozen_shaped",
    "initial_state",
    "run_steps",
]


def _float_array(values, name: str) -> np.ndarray:
    try:
        return np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numbers, got {values!r}") from None


def _freeze(arr: np.ndarray, name: str) -> np.ndarray:
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    arr.setflags(write=False)
    return arr


def frozen_array(values, n: int | None, name: str) -> np.ndarray:
    """Read-only, finite 1-D float copy of ``values`` (flattened).

    Parameters
    ----------
    values : array_like
        Numbers to copy.
    n : int or None
        Number of values required; ``None`` accepts any number.
    name : str
        Name used in the error messages.

    Raises
    ------
    ValueError
        If ``values`` are not numbers, do not number ``n`` or are not all finite.
    """
    arr = _float_array(values, name).reshape(-1)
    if n is not None and arr.shape != (n,):
        raise ValueError(f"{name} must have {n} values, got {arr.size}")
    return _freeze(arr, name)


def freeze_arrays(record, **sizes: int | None) -> None:
    """Replace each named field of the frozen dataclass ``record`` by :func:`frozen_array` of
    it, ``sizes`` giving the number of values each needs (``None``: any), in that order."""
    for name, n in sizes.items():
        object.__setattr__(record, name, frozen_array(getattr(record, name), n, name))


def finite_floats(record, *names: str) -> None:
    """Replace each named field of the frozen dataclass ``record`` by its float value.

    Raises
    ------
    ValueError
        If one is not finite (checked in the order given).
    """
    for name in names:
        value = float(getattr(record, name))
        if not np.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value}")
        object.__setattr__(record, name, value)


def frozen_shaped(values, shape: tuple[int, ...] | None, name: str) -> np.ndarray:
    """Read-only, finite float copy of ``values`` of exactly ``shape`` (any shape if ``None``).

    Unlike :func:`frozen_array` the values are not flattened, so tables keep their layout.
    """
    arr = _float_array(values, name)
    if shape is not None and arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {arr.shape}")
    return _freeze(arr, name)


def check_signal(u, name: str) -> np.ndarray:
    """``u`` as a contiguous, non-empty, finite 1-D float array, read-only (the kernels that
    read it then see one array type, :func:`hystkit._kernel_inputs.read_only`).

    Raises
    ------
    ValueError
        If ``u`` is not 1-D or is empty, or if it holds NaN or inf (the message names the index
        of the first such sample).
    """
    u = np.ascontiguousarray(u, dtype=float)
    if u.ndim != 1 or u.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D array, got shape {u.shape}")
    if not np.all(np.isfinite(u)):
        raise ValueError(f"{name} contains NaN or inf at index {int(np.argmin(np.isfinite(u)))}")
    return read_only(u)


def broadcast_state(x0, n: int, layout: str | None = None) -> np.ndarray:
    """A given initial state ``x0`` (a float or ``n`` values) as a fresh array of ``n`` floats.

    Parameters
    ----------
    layout : str, optional
        What the ``n`` values are; if given, a ``x0`` that does not broadcast to ``n`` values is
        reported with it, otherwise numpy's broadcasting error propagates.

    Raises
    ------
    ValueError
        If ``x0`` does not broadcast to ``(n,)`` or is not finite.
    """
    try:
        x0 = np.broadcast_to(np.asarray(x0, dtype=float), (n,)).copy()
    except ValueError:
        if layout is None:
            raise
        raise ValueError(f"x0 must be a float or have {n} values ({layout}), "
                         f"got shape {np.shape(x0)}") from None
    if not np.all(np.isfinite(x0)):
        raise ValueError("x0 must be finite")
    return x0


def initial_state(n: int, x0, at_rest: float, layout: str | None = None) -> np.ndarray:
    """Initial state of ``n`` values: all ``at_rest`` if ``x0`` is None, else ``x0`` broadcast.

    See :func:`broadcast_state` for ``layout`` and the errors.
    """
    if x0 is None:
        return np.full(n, float(at_rest))
    return broadcast_state(x0, n, layout)


def check_positive_int(value, name: str) -> None:
    """Raise ValueError unless ``value`` is a whole number >= 1 (model sizes)."""
    # inf, NaN, text and None are refused here too (int() would raise OverflowError/TypeError)
    if not isinstance(value, int | float | np.integer | np.floating) or not np.isfinite(value) \
            or int(value) != value or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")


def check_cells(n: int, dt: float, slope_cap: float, name: str = "n_cells") -> None:
    """The checks of a cell (or element, section) model's structure: ``n`` a positive integer
    (:func:`check_positive_int` under ``name``), then :func:`check_dt` and
    :func:`check_slope_cap`."""
    check_positive_int(n, name)
    check_dt(dt)
    check_slope_cap(slope_cap)


def check_size(ours: int, theirs: int, what: str) -> None:
    """Raise ValueError unless params and structure agree on the number of ``what``.

    ``ours`` is the count the parameters carry, ``theirs`` the structure's.
    """
    if ours != theirs:
        raise ValueError(f"params have {ours} {what}, structure has {theirs}")


def check_dt(dt: float) -> None:
    """Raise ValueError unless the sample time ``dt`` is a positive finite number of seconds."""
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")


def check_slope_cap(slope_cap: float) -> None:
    """Raise ValueError unless ``0 < slope_cap < 2``, the forward-Euler stability limit.

    ``slope_cap`` bounds ``f'(v) dt`` of a cell's resistor; eq. 5.28 requires it below 2.
    """
    if not 0 < slope_cap < 2:
        raise ValueError(f"slope_cap must lie in (0, 2) for a stable Euler step (eq. 5.28), "
                         f"got {slope_cap!r}")


def run_steps(step, structure, params, u: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, Any]:
    """Readable reference run: ``step(structure, params, x, u_n) -> (y_n, x_next)`` called for
    every sample of ``u`` (already checked) from the state ``x``; returns ``(y, x_end)``."""
    y = np.empty_like(u)
    for n, u_n in enumerate(u):
        y[n], x = step(structure, params, x, u_n)
    return y, x


def check_finite_run(values: np.ndarray, family: str, what: str = "output") -> np.ndarray:
    """Return `values` when all are finite; otherwise raise `FitDivergedError` naming the family
    and the first bad sample, so no inf/NaN ever leaves a model run."""
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise FitDivergedError(f"the {family} model's {what} left the finite range at sample "
                               f"{int(bad[0]) + 1} of {np.size(values)}: the parameters lie "
                               f"outside the domain where it stays bounded")
    return values


# Weights and biases in normalised units (eq. 5.10; the fits keep |w| <= 100): beyond 1e6 a
# model maps [-1, 1] data to nonsense, and sums of them stay finite for any sane input.
MAX_VALUE = 1e6


def check_range(values, name: str, low: float, high: float, why: str = "") -> None:
    """Raise ValueError unless every value lies in ``[low, high]`` (NaN fails); the message
    names the parameter, the first offending value and the range."""
    arr = np.asarray(values, dtype=float).reshape(-1)
    bad = ~((arr >= low) & (arr <= high))
    if np.any(bad):
        raise ValueError(f"{name} must lie in [{low:g}, {high:g}]{why}, got "
                         f"{float(arr[np.argmax(bad)])!r}")


def check_magnitude(values, name: str, limit: float = MAX_VALUE) -> None:
    """Raise ValueError unless ``|values| <= limit`` (normalised units, see ``MAX_VALUE``)."""
    check_range(values, name, -limit, limit, " (normalised units: the domain where runs stay "
                                             "bounded)")


def check_structure_size(n, name: str, limit: int, low: int = 1) -> None:
    """Raise ValueError unless ``n`` is a whole number in ``[low, limit]``; checked before any
    other field, so nothing is allocated or looped over for a huge or non-numeric size."""
    ok = (isinstance(n, int | float | np.integer | np.floating) and not isinstance(n, bool)
          and np.isfinite(n) and int(n) == n and low <= n <= limit)
    if not ok:
        raise ValueError(f"{name} must be a whole number in [{low}, {limit}], got {n!r}")
