"""A compensator sample by sample: the same numbers as :meth:`Compensator.estimate`, live.

A stream carries everything a recording's run would have remembered in an explicit
:class:`StreamState`: the model's state vector, the centring's running sums and the sample
counter. :func:`advance` is the pure core (``state`` in, estimates and the next state out);
:class:`Stream` is a thin holder of the present state for an acquisition loop or a ROS node.

Running a recording through a stream in chunks of any size gives exactly (bit for bit) the
offline :meth:`Compensator.estimate`: every chunk goes through the same data path (the centring's
running mean / low-pass continued from the stored state, the polarity, the scaling) and the
family's compiled ``simulate`` / ``invert`` continued from the stored model state, which equals
the whole run for every family (the PI inverse to rounding: it rebuilds its inverse-play states
from the forward state at each chunk start).

That is the readable path (:func:`advance`). :class:`Stream` runs the same arithmetic compiled,
one kernel call per sample or chunk with the state in arrays (:mod:`._stream_kernel`), when the
family's compiled block reproduces the offline run bit for bit, which each stream checks on a
probe signal when it is made; otherwise (a family whose output is summed by numpy after its
kernel, the PI inverse), for the first sample of a stream at rest and for a refused sample, it
takes the readable path.

Start-up (``start``):

- ``"rest"``: the model at rest at the first sample (what ``estimate`` does);
- ``"sync"``: the state left by the synchronisation excitation (eq. 2.21-2.22,
  :func:`sync_excitation`), once the device has been driven through it;
- an array: a given model state (for example one saved from an earlier run).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..compensation import Compensator, load_compensator
from ..errors import FitDivergedError, InputError
from ._readable import (
    StartUp,
    _advance,
    _advance_one,
    _Path,
    _Previous,
    advance,
    check_streamable,
    initial_state,
)
from ._stream_output import (
    StepOutput,
    StreamOutput,
    _as_chunk,
    _chunk_output,
    _concatenate,
    _step_output,
)
from ._stream_probe import compiled_engine
from ._stream_state import StreamState

__all__ = ["StartUp", "StepOutput", "Stream", "StreamOutput", "StreamState", "advance",
           "check_streamable", "initial_state"]


class Stream:
    """A compensator running live: one sensor sample (or chunk) in, position estimates out.

    Parameters
    ----------
    compensator : Compensator
        Any deployable compensator (centring ``fit``, ``tare``, ``track`` or ``none``), direct or
        inverse, of any family.
    start : "rest", "sync" or array
        Start-up, default ``"rest"``: ``"rest"``: the model at rest at the first sample (what ``estimate``
        does); ``"sync"``: the state left by the synchronisation excitation (eq. 2.21-2.22,
        :func:`sync_excitation`), once the device has been driven through it; an array: a
        given model state (its length is the family's state size), e.g. one saved from an
        earlier run.
    rest_position : float, optional
        Where the device rests during the tare window [mm], if not where it rested in training
        (``tare`` only; as :meth:`Compensator.estimate`).
    label : str
        Names the stream in error messages.
    level : float, optional
        Nominal coverage of the prediction band in the outputs (``lower``, ``upper``; a
        compensator without a band gives None); default the band's own.

    Notes
    -----
    The object holds only the present :class:`StreamState` (``state`` gives it, ``from_state``
    resumes from one); two signals need two streams. :func:`advance` is the same computation
    without an object.

    Samples run through one compiled kernel (:mod:`._stream_kernel`) when the family's compiled
    block gives the offline run's bits, which is checked on a probe signal when the stream is
    made (``compiled`` says the outcome); otherwise, for the first sample of a stream at rest
    and for a sample the kernel refuses, through the readable Python path. Both give the same
    bits (tested).
    """

    def __init__(self, compensator: Compensator, start: StartUp = "rest", *,
                 rest_position: float | None = None, label: str = "stream",
                 level: float | None = None) -> None:
        self._path = _Path(compensator, rest_position, level)
        self._state = initial_state(compensator, start)
        self._previous: _Previous | None = None  # speeds up step; never changes a result
        self._engine = compiled_engine(self._path)
        # Where the present state is: in _state, in the engine's arrays, or in both.
        self._state_ok, self._engine_ok = True, False
        self.label = label

    @classmethod
    def from_state(cls, compensator: Compensator, state: StreamState, *,
                   rest_position: float | None = None, label: str = "stream",
                   level: float | None = None) -> Stream:
        """Resume a stream from a saved :class:`StreamState`."""
        stream = cls(compensator, rest_position=rest_position, label=label, level=level)
        if state.x is not None:
            initial_state(compensator, state.x)  # checks its size
        elif state.n_samples:
            raise InputError(f"stream state: {state.n_samples} samples seen but no model state")
        stream._set_state(state)
        return stream

    @classmethod
    def from_file(cls, model_path: str | Path, start: StartUp = "rest", **options) -> Stream:
        """A stream of the compensator in a model file (``hystkit fit`` output)."""
        return cls(load_compensator(model_path), start, **options)

    @property
    def compensator(self) -> Compensator:
        return self._path.comp

    @property
    def compiled(self) -> bool:
        """Whether samples run through the compiled kernel (see the class notes)."""
        return self._engine is not None

    @property
    def state(self) -> StreamState:
        """The present state (immutable; safe to keep and to resume from)."""
        if not self._state_ok:
            self._state, self._state_ok = self._engine.state(), True
        return self._state

    def _set_state(self, state: StreamState) -> None:
        self._state, self._state_ok, self._engine_ok = state, True, False

    def _engine_ready(self) -> bool:
        """Whether the next sample can run compiled: there is an engine and it holds the
        present state (loaded now if needed; a stream at rest has no model state before its
        first sample, which the Python path takes)."""
        if self._engine is None:
            return False
        if not self._engine_ok:
            if self._state.x is None:
                return False
            self._engine.load(self._state)
            self._engine_ok = True
        return True

    def step(self, sensor: float) -> float:
        """Estimate [mm] for one raw sensor sample (the same bits as :meth:`process`)."""
        return self.step_flagged(sensor).estimate

    def step_flagged(self, sensor: float) -> StepOutput:
        """Estimate and use-time flags for one raw sensor sample."""
        if self._engine_ready():
            column = self._engine.step(sensor)
            if column is not None:
                self._state_ok = False
                return _step_output(self._path, column)
        return self._step_python(sensor)

    def _step_python(self, sensor: float) -> StepOutput:
        """:meth:`step_flagged` through the readable Python path (the reference the compiled
        kernel is checked against; a refused sample raises here)."""
        out, state, self._previous = _advance_one(self._path, self.state, sensor, self.label,
                                                  self._previous)
        self._set_state(state)
        return out

    def step_many(self, sensor: np.ndarray) -> StreamOutput:
        """:meth:`step_flagged` on each sample of a chunk in turn (compiled: one call for the
        chunk), up to the first sample whose estimate is refused as a runaway: the state is
        then the one before it, and ``step_flagged`` on it raises FitDivergedError saying why.

        Returns
        -------
        StreamOutput
            The samples taken: fewer than `sensor` holds when one was refused.
        """
        s_raw = np.ascontiguousarray(sensor, dtype=np.float64).reshape(-1)
        parts, k = [], 0
        while k < s_raw.size:
            if self._engine_ready():
                out, n = self._engine.run(s_raw[k:])
                if n:
                    self._state_ok = False
                    parts.append(_chunk_output(self._path, out[:, :n]))
                k += n
                if k == s_raw.size:
                    break
            try:  # the Python path: a stream's first sample, or one the kernel refused
                parts.append(_as_chunk(self._path, self._step_python(s_raw[k])))
            except FitDivergedError:
                break
            k += 1
        return _concatenate(self._path, parts)

    def process(self, sensor: np.ndarray) -> np.ndarray:
        """Estimates [mm] for a chunk of raw sensor samples (compiled per chunk)."""
        return self.process_flagged(sensor).estimate

    def process_flagged(self, sensor: np.ndarray) -> StreamOutput:
        """Estimates and use-time flags for a chunk; see :class:`StreamOutput`. A chunk with
        a refused sample raises FitDivergedError, the state left as it was."""
        s_raw = np.ascontiguousarray(sensor, dtype=np.float64).reshape(-1)
        before = self.state
        if self._engine is not None and s_raw.size:
            try:
                out = self.step_many(s_raw)
            except BaseException:
                self._set_state(before)
                raise
            if out.estimate.size == s_raw.size:
                return out
            self._set_state(before)  # the Python path raises for the chunk, as offline
        out, state = _advance(self._path, before, s_raw, self.label)
        self._set_state(state)
        return out
