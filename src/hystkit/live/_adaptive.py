"""Online adaptation: a stream that re-fits its output's linear parameters from occasional
reference positions (paper 9.1's proposal), by recursive least squares with forgetting.

The compensator's estimate is linear in a few output parameters, whatever the model's memory:

- ``"gain"`` (any family, either mode): ``estimate = a * y_hat + b`` with ``y_hat`` the plain
  stream's estimate [mm]; ``theta = (a, b)`` starts at ``(1, 0)``. A drifting sensor gain, a
  baseline shift and a changed mounting show up (to first order) as a gain and an offset here.
- ``"weights"`` (direct compensators whose parameters have output weights ``w`` and a bias
  ``v_b``, eq. 5.2: mPL, PL, ladder; not mPL-poly, whose output passes the cubic ``g`` of
  eq. 5.17 and fails the probe run below): ``estimate = sum_k a_k c_k + b`` with
  ``c_k = position_scale * w_k * y_k`` the k-th cell's contribution [mm] (``y_k`` the cell's
  output, from a run with unit weight ``k``), ``a_k`` its multiplier (starts at 1) and ``b``
  the offset correction [mm] (starts at 0). The cells' states do not depend on the weights, so
  the regressors are exact; the linearity is checked on a probe run when the stream is made.

Each sample with a known reference ``r`` [mm] updates ``theta`` (:func:`~._rls.rls_update`)
*after* that sample's estimate is made: the estimate never sees its own reference (so its
error against the reference is an honest prediction error). Until the first reference the
output is the plain stream's, bit for bit; a chunk of any size gives the same bits as the same
samples one by one.

Every reference is checked for plausibility before it moves anything (:class:`Plausible`): it
must lie within the training positions widened by ``REFERENCE_MARGIN`` of their extent, and
differ from the sample's estimate by at most ``MAX_INNOVATION`` extents; otherwise it is
rejected and counted (``AdaptiveState.n_rejected``). An update that would take the output
parameters out of their domain (a multiplier beyond ``MAX_MULTIPLIER`` or its reciprocal for
``gain``, beyond ``MAX_MULTIPLIER`` in magnitude or out of the family's parameter domain for
``weights``, an offset beyond one extent, or anything not finite) is refused and counted
(``n_refused``): the parameters stay where they were. One reference of 1e20 mm used to set the
gain to 2.7e17; one of 1e200 ended the stream with an OverflowError.

The prediction band (:mod:`._band`) follows the references too, by online quantile tracking
on a log scale (Angelopoulos, Candès & Tibshirani 2023, "Conformal PID control", the P part):
the band is the plain stream's half-width times the adapted gain's magnitude (``gain``) times a
multiplier ``m``; each plausible reference moves ``log m`` by ``BAND_STEP * (miss - alpha)``,
``miss`` being 1 if the reference fell outside the sample's band and ``alpha = 1 - level``. Over
the references the share of misses approaches ``alpha`` whatever the drift, as long as the
multiplier can follow it (within ``[1 / MAX_BAND_FACTOR, MAX_BAND_FACTOR]``).

Re-fitting the whole model (cell dynamics too) on a sliding window: :mod:`._refit`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..compensation import Compensator
from ..errors import InputError
from ._adaptive_plan import _Plan
from ._adaptive_records import (
    ADAPT_PARAMETERS,
    BAND_STEP,
    MAX_INNOVATION,
    MAX_MULTIPLIER,
    REFERENCE_MARGIN,
    Adaptation,
    AdaptiveState,
    Plausible,
    reference_column,
)
from ._readable import StartUp, _advance, _advance_one, _Previous, initial_state
from ._stream import Stream
from ._stream_output import StepOutput, StreamOutput, _outside

__all__ = ["ADAPT_PARAMETERS", "BAND_STEP", "MAX_INNOVATION", "MAX_MULTIPLIER", "REFERENCE_MARGIN",
           "Adaptation", "AdaptiveState", "AdaptiveStream", "Plausible", "advance_adaptive"]


def _advance_plan(plan: _Plan, state: AdaptiveState, sensor: np.ndarray,
                  reference: np.ndarray | None,
                  label: str) -> tuple[StreamOutput, AdaptiveState]:
    s_raw = np.ascontiguousarray(sensor, dtype=np.float64).reshape(-1)
    r = reference_column(reference, s_raw.size, state.stream.n_samples, label)
    plain, stream_next = _advance(plan.path, state.stream, s_raw, label)
    if s_raw.size == 0:
        return plain, state
    phi = plan.regressors(state.stream, s_raw, plain.estimate)
    estimate = np.empty(s_raw.size)
    banded = plain.lower is not None
    plain_half = plain.upper - plain.estimate if banded else None
    lower, upper = (np.empty(s_raw.size), np.empty(s_raw.size)) if banded else (None, None)
    learnt, begin = state, 0
    for i in [*np.flatnonzero(np.isfinite(r)).tolist(), s_raw.size]:
        part = slice(begin, min(i + 1, s_raw.size))
        estimate[part] = plan.predict(learnt.rls, phi[part], plain.estimate[part])
        half = None
        if banded:
            if plan.untouched(learnt):  # the plain band, bit for bit, until a reference
                lower[part], upper[part] = plain.lower[part], plain.upper[part]
            else:
                half = plan.half_width(learnt, plain_half[part])
                lower[part], upper[part] = estimate[part] - half, estimate[part] + half
        if i < s_raw.size:
            learnt = plan.learn(learnt, phi[i], r[i], estimate[i],
                                None if not banded else float(upper[i] - estimate[i]))
        begin = i + 1
    out = StreamOutput(estimate, plain.sensor_outside,
                       _outside(estimate, plan.path.estimate_bounds), lower, upper)
    return out, dataclasses.replace(learnt, stream=stream_next)


def advance_adaptive(comp: Compensator, adaptation: Adaptation, state: AdaptiveState,
                     sensor: np.ndarray, reference: np.ndarray | None = None, *,
                     rest_position: float | None = None, label: str = "stream",
                     level: float | None = None) -> tuple[StreamOutput, AdaptiveState]:
    """Run one chunk of raw sensor samples with references [mm] (NaN: unknown).

    Pure, as :func:`~._stream.advance`; ``state`` comes from :attr:`AdaptiveStream.state`
    or a previous call.

    Parameters
    ----------
    comp : Compensator
        The compensator; ``"weights"`` needs a direct one with weights ``w``, ``v_b``.
    adaptation : Adaptation
        What to re-fit and how fast to forget; the same for every chunk of a stream.
    state : AdaptiveState
        Where the stream is.
    sensor : numpy.ndarray, shape (n,)
        The chunk's raw sensor samples [sensor units]; may be empty.
    reference : numpy.ndarray, shape (n,), optional
        Reference position per sample [mm], NaN where unknown; None: none known.
    rest_position : float, optional
        Where the device rests during the tare window [mm] (``tare`` only; as
        :class:`~._stream.Stream`).
    label : str, default "stream"
        Names the stream in error messages.
    level : float, optional
        Nominal coverage of the band; default the band's own.

    Returns
    -------
    output : StreamOutput
        The chunk's adapted estimates [mm], their adapted band and the use-time flags
        (``estimate_outside`` of the adapted estimate).
    state : AdaptiveState
        The state after the chunk's last sample and its references.

    Raises
    ------
    InputError
        If ``reference`` has not one value per sensor sample or holds an infinite one, or
        ``"weights"`` does not apply to ``comp`` (inverse, no weights, or not linear in them).
    FitDivergedError
        As :func:`~._stream.advance`.
    """
    return _advance_plan(_Plan(comp, adaptation, rest_position, level), state, sensor,
                         reference, label)


class AdaptiveStream:
    """A :class:`~._stream.Stream` whose output parameters follow occasional references.

    Parameters
    ----------
    compensator : Compensator
        Any deployable compensator; ``"weights"`` needs a direct one with weights ``w``, ``v_b``.
    adaptation : Adaptation, optional
        What to re-fit and how fast to forget (default: gain and offset, lambda = 0.9).
    start, rest_position, label, level
        As :class:`~._stream.Stream`; the band (if the compensator has one) follows the
        references (module docstring).

    Notes
    -----
    Holds only the present :class:`AdaptiveState`; :func:`advance_adaptive` is the same
    computation without an object.
    """

    def __init__(self, compensator: Compensator, adaptation: Adaptation | None = None,
                 start: StartUp = "rest", *, rest_position: float | None = None,
                 label: str = "stream", level: float | None = None) -> None:
        self._plan = _Plan(compensator, adaptation or Adaptation(), rest_position, level)
        self._state = AdaptiveState(initial_state(compensator, start), self._plan.start)
        self._previous: _Previous | None = None  # speeds up step; never changes a result
        self.label = label

    @classmethod
    def from_state(cls, compensator: Compensator, adaptation: Adaptation,
                   state: AdaptiveState, *, rest_position: float | None = None,
                   label: str = "stream") -> AdaptiveStream:
        """Resume an adapting stream from a saved :class:`AdaptiveState`."""
        stream = cls(compensator, adaptation, rest_position=rest_position, label=label)
        plain = Stream.from_state(compensator, state.stream)  # checks the model state
        if state.rls.theta.shape != stream._plan.start.theta.shape:
            raise InputError(f"adaptive stream state: {state.rls.theta.size} output parameters, "
                             f"the {adaptation.parameters!r} adaptation of this compensator "
                             f"has {stream._plan.start.theta.size}")
        stream._state = dataclasses.replace(state, stream=plain.state)
        return stream

    @property
    def compensator(self) -> Compensator:
        return self._plan.path.comp

    @property
    def state(self) -> AdaptiveState:
        """The present state (immutable)."""
        return self._state

    @property
    def n_rejected(self) -> int:
        """References rejected as implausible so far (:class:`Plausible`)."""
        return self._state.n_rejected

    @property
    def n_refused(self) -> int:
        """Updates refused so far: they would have left the output parameters' domain."""
        return self._state.n_refused

    @property
    def parameters(self) -> dict[str, float]:
        """The present output parameters by name (multipliers, then ``offset_mm``)."""
        return dict(zip(self._plan.names, self._state.rls.theta.tolist(), strict=True))

    def step(self, sensor: float, reference: float = float("nan")) -> float:
        """Estimate [mm] for one raw sensor sample; then learn from ``reference`` if known."""
        return self.step_flagged(sensor, reference).estimate

    def step_flagged(self, sensor: float, reference: float = float("nan")) -> StepOutput:
        """Estimate and use-time flags for one raw sensor sample (the same bits as
        :meth:`process`); then learn from ``reference`` [mm] if known."""
        if self._plan.adaptation.parameters != "gain":
            out = self.process_flagged(np.array([sensor]), np.array([reference]))
            return StepOutput(float(out.estimate[0]),
                              *(None if f is None else bool(f[0]) for f in out[1:3]),
                              *(None if b is None else float(b[0]) for b in out[3:]))
        # gain: the plain stream's fast one-sample path (the same bits as its chunks), then
        # the same prediction and update as a chunk's
        r = reference_column(np.array([reference]), 1, self._state.stream.n_samples, self.label)[0]
        plain, stream_next, self._previous = _advance_one(
            self._plan.path, self._state.stream, sensor, self.label, self._previous)
        phi = np.array([[plain.estimate, 1.0]])
        learnt = self._state
        estimate = float(self._plan.predict(learnt.rls, phi, np.array([plain.estimate]))[0])
        band = (None, None)
        if plain.lower is not None and self._plan.untouched(learnt):
            band = (plain.lower, plain.upper)
        elif plain.lower is not None:  # the chunk path's operations on one-element arrays
            half = self._plan.half_width(
                learnt, np.array([plain.upper]) - np.array([plain.estimate]))
            band = (float((np.array([estimate]) - half)[0]),
                    float((np.array([estimate]) + half)[0]))
        if np.isfinite(r):
            learnt = self._plan.learn(learnt, phi[0], r, estimate,
                                      None if band[1] is None else band[1] - estimate)
        self._state = dataclasses.replace(learnt, stream=stream_next)
        return StepOutput(estimate, plain.sensor_outside,
                          _outside(estimate, self._plan.path.estimate_bounds), *band)

    def process(self, sensor: np.ndarray, reference: np.ndarray | None = None) -> np.ndarray:
        """Estimates [mm] for a chunk; ``reference`` [mm] per sample, NaN where unknown."""
        return self.process_flagged(sensor, reference).estimate

    def process_flagged(self, sensor: np.ndarray,
                        reference: np.ndarray | None = None) -> StreamOutput:
        """Estimates and use-time flags (of the adapted estimate) for a chunk."""
        out, self._state = _advance_plan(self._plan, self._state, sensor, reference,
                                         self.label)
        return out
