"""What a stream gives: one chunk's results (:class:`StreamOutput`), one sample's
(:class:`StepOutput`), the use-time flags, and the outputs of the compiled kernel's rows
(:mod:`._stream_kernel`) in these forms."""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from ._readable import _Path

__all__ = ["StepOutput", "StreamOutput"]


class StreamOutput(NamedTuple):
    """One chunk's results: estimates [mm] and the use-time guards of ``hystkit compensate``.

    ``sensor_outside`` / ``estimate_outside`` are None when the model file does not know the
    training ranges (files from before they were stored).

    Parameters
    ----------
    estimate : numpy.ndarray, shape (n,)
        Position estimate [mm], one per sensor sample of the chunk.
    sensor_outside : numpy.ndarray of bool, shape (n,), or None
        Samples whose normalised sensor lies outside the training range plus its margin
        (:meth:`Compensator.sensor_outside`).
    estimate_outside : numpy.ndarray of bool, shape (n,), or None
        Estimates outside the training positions plus their margin
        (:meth:`Compensator.estimate_outside`).
    lower, upper : numpy.ndarray, shape (n,), or None
        The prediction band [mm] (:meth:`Compensator.estimate_with_band`); None without one.
    """

    estimate: np.ndarray
    sensor_outside: np.ndarray | None
    estimate_outside: np.ndarray | None
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None


class StepOutput(NamedTuple):
    """One sample's result: estimate [mm] and its use-time guards (None: ranges unknown).

    Parameters
    ----------
    estimate : float
        Position estimate [mm].
    sensor_outside : bool or None
        The sensor sample is outside the training range plus its margin.
    estimate_outside : bool or None
        The estimate is outside the training positions plus their margin.
    lower, upper : float or None
        The prediction band [mm]; None without one.
    """

    estimate: float
    sensor_outside: bool | None
    estimate_outside: bool | None
    lower: float | None = None
    upper: float | None = None


def _flags(path: _Path, s: np.ndarray | float,
           estimate: np.ndarray | float) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Masks (or booleans, for scalars) of ``Compensator.sensor_outside`` / ``estimate_outside``."""
    return _outside(s, path.sensor_bounds), _outside(estimate, path.estimate_bounds)


def _outside(values, bounds: tuple[float, float] | None):
    if bounds is None:
        return None
    return (values < bounds[0]) | (values > bounds[1])


def _step_output(path: _Path, column: list[float]) -> StepOutput:
    """A sample's StepOutput from its column of the kernel's ``out``."""
    estimate, lower, upper, sensor_outside, estimate_outside = column
    return StepOutput(estimate,
                      None if path.sensor_bounds is None else sensor_outside != 0.0,
                      None if path.estimate_bounds is None else estimate_outside != 0.0,
                      *((None, None) if path.comp.band is None else (lower, upper)))


def _chunk_output(path: _Path, rows: np.ndarray) -> StreamOutput:
    """A chunk's StreamOutput from the kernel's ``out`` rows."""
    estimate, lower, upper, sensor_outside, estimate_outside = rows
    return StreamOutput(estimate.copy(),
                        None if path.sensor_bounds is None else sensor_outside != 0.0,
                        None if path.estimate_bounds is None else estimate_outside != 0.0,
                        *((None, None) if path.comp.band is None else (lower.copy(),
                                                                       upper.copy())))


def _as_chunk(path: _Path, out: StepOutput) -> StreamOutput:
    """One sample's StepOutput as a chunk of one."""
    return StreamOutput(*(None if v is None else np.array([v]) for v in out))


def _concatenate(path: _Path, parts: list[StreamOutput]) -> StreamOutput:
    """Chunks' outputs joined (no chunk: an empty output)."""
    if not parts:
        empty = np.empty(0)
        band = (None, None) if path.comp.band is None else (empty, empty)
        flags = _flags(path, empty, empty)
        return StreamOutput(empty, *flags, *band)
    if len(parts) == 1:
        return parts[0]
    return StreamOutput(*(None if values[0] is None else np.concatenate(values)
                          for values in zip(*parts, strict=True)))
