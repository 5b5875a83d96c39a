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
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..compensation._compensator import Compensator
from ..errors import InputError
from ._rls import RlsState, rls_bound, rls_start, rls_update
from ._stream import (
    StartUp,
    StepOutput,
    Stream,
    StreamOutput,
    StreamState,
    _advance,
    _advance_one,
    _outside,
    _Path,
    _Previous,
    _sensor_offset,
    initial_state,
)

__all__ = ["ADAPT_PARAMETERS", "BAND_STEP", "MAX_INNOVATION", "MAX_MULTIPLIER", "REFERENCE_MARGIN",
           "Adaptation", "AdaptiveState", "AdaptiveStream", "Plausible", "advance_adaptive"]

ADAPT_PARAMETERS = ("gain", "weights")
# Relative error allowed between a model's output and its weighted cell outputs on the probe
# run: rounding of a sum of a few hundred terms, far below any non-linearity in the weights.
LINEARITY_TOLERANCE = 1e-9
# Plausible references, in extents of the training positions (their span; module docstring):
# a reference beyond the training positions widened by REFERENCE_MARGIN extents on each side, or
# further than MAX_INNOVATION extents from the estimate, is no drift but a wrong reference.
REFERENCE_MARGIN = 0.5
MAX_INNOVATION = 1.0
# The output parameters' domain: a gain moved by more than this factor (or a cell's weight
# multiplier beyond it in magnitude) is no drift but another sensor; fit again.
MAX_MULTIPLIER = 10.0
# Quantile tracking of the band: log m moves by BAND_STEP (1 - alpha) at a miss, by
# -BAND_STEP alpha at a hit (a miss widens the 90 % band by 20 %, nine hits narrow it back).
BAND_STEP = 0.2
MAX_BAND_FACTOR = 100.0


@dataclass(frozen=True)
class Adaptation:
    """How a stream adapts.

    Parameters
    ----------
    parameters : {"gain", "weights"}
        Which output parameters RLS re-fits (module docstring).
    forgetting : float
        Forgetting factor ``lambda`` in (0, 1], per reference sample: the estimate remembers
        about ``1 / (1 - lambda)`` references (1: never forgets).
    prior_gain : float
        Prior standard deviation of each multiplier (``a``, ``a_k``), relative (0.1: 10 %).
    prior_offset : float or None
        Prior standard deviation of the offset ``b`` [mm]; None: 10 % of the training
        positions' span (1 mm if the model file does not know it).
    reference_margin : float, default REFERENCE_MARGIN
        A reference [mm] beyond the training positions widened by this many extents of them
        on each side is rejected (:class:`Plausible`; ``inf``: no such check).
    max_innovation : float, default MAX_INNOVATION
        A reference further than this many extents of the training positions from the
        sample's estimate is rejected (``inf``: no such check).
    """

    parameters: str = "gain"
    forgetting: float = 0.9
    prior_gain: float = 0.1
    prior_offset: float | None = None
    reference_margin: float = REFERENCE_MARGIN
    max_innovation: float = MAX_INNOVATION

    def __post_init__(self) -> None:
        if self.parameters not in ADAPT_PARAMETERS:
            raise InputError(f"adaptation parameters {self.parameters!r}: use one of "
                             f"{', '.join(ADAPT_PARAMETERS)}")
        if not 0.0 < self.forgetting <= 1.0:
            raise InputError(f"forgetting factor {self.forgetting!r}: must be in (0, 1]")
        for name in ("prior_gain", "prior_offset"):
            value = getattr(self, name)
            if value is not None and not (0.0 < value < float("inf")):
                raise InputError(f"{name} {value!r}: must be a finite positive number")
        for name in ("reference_margin", "max_innovation"):
            if not getattr(self, name) > 0.0:  # inf allowed: no such check
                raise InputError(f"{name} {getattr(self, name)!r}: must be a positive number")


@dataclass(frozen=True, eq=False)
class AdaptiveState:
    """The plain stream's state and the RLS state of the output parameters.

    Parameters
    ----------
    stream : StreamState
        The plain (un-adapted) stream's state.
    rls : RlsState
        Estimate and covariance of the output parameters (multipliers, then the offset [mm]).
    n_rejected : int, default 0
        References rejected as implausible (:class:`Plausible`); they moved nothing.
    n_refused : int, default 0
        Plausible references whose update would have left the output parameters' domain;
        refused, they moved nothing either.
    band_log_factor : float, default 0.0
        ``log m`` of the band's multiplier (module docstring).
    n_band_misses : int, default 0
        Plausible references that fell outside their sample's band.
    n_band_checks : int, default 0
        Plausible references checked against their sample's band.
    """

    stream: StreamState
    rls: RlsState
    n_rejected: int = 0
    n_refused: int = 0
    band_log_factor: float = 0.0
    n_band_misses: int = 0
    n_band_checks: int = 0


@dataclass(frozen=True)
class Plausible:
    """Where a reference [mm] is believed: the training positions ``(low, high)`` widened by
    ``margin`` extents, and within ``innovation`` extents of the sample's estimate.

    Parameters
    ----------
    low, high : float
        The training positions [mm] (shifted by the centring's position offset in use).
    extent : float
        Their extent [mm] (> 0): the unit of the margins and of the offset's domain.
    margin : float, default REFERENCE_MARGIN
        Extents by which the range is widened on each side.
    innovation : float, default MAX_INNOVATION
        Largest distance from the estimate, in extents.
    """

    low: float
    high: float
    extent: float
    margin: float = REFERENCE_MARGIN
    innovation: float = MAX_INNOVATION

    @classmethod
    def of(cls, comp: Compensator, position_offset: float,
           adaptation: Any = None) -> Plausible:
        """The bounds of a compensator: its stored training positions, or (older files) the
        positions its scaling maps [-1, 1] to.

        Parameters
        ----------
        comp : Compensator
            The compensator.
        position_offset : float
            The position offset [mm] in use (the stream's; shifts the stored range as
            :meth:`Compensator.estimate_outside` does).
        adaptation : Adaptation or Refit, optional
            Its ``reference_margin`` and ``max_innovation`` (default: the module's).

        Returns
        -------
        Plausible
            Its bounds.
        """
        gates = (REFERENCE_MARGIN, MAX_INNOVATION) if adaptation is None else (
            adaptation.reference_margin, adaptation.max_innovation)
        scale = comp.scaling.position_scale
        if comp.position_range is None:
            return cls(position_offset - scale, position_offset + scale, 2.0 * scale, *gates)
        lo, hi = comp.position_range
        shift = position_offset - comp.scaling.position_offset
        return cls(lo + shift, hi + shift, (hi - lo) if hi > lo else scale, *gates)

    def why_not(self, reference: float, estimate: float) -> str | None:
        """None if `reference` [mm] is plausible at a sample estimated at `estimate` [mm],
        else why not.

        Parameters
        ----------
        reference, estimate : float
            The reference and the sample's estimate before learning from it [mm].

        Returns
        -------
        str or None
            ``"range"`` or ``"innovation"``, or None.
        """
        with np.errstate(invalid="ignore"):  # inf * 0 extents: no check
            pad = self.margin * self.extent
            if not self.low - pad <= reference <= self.high + pad:
                return "range"
            if not abs(reference - estimate) <= self.innovation * self.extent:
                return "innovation"
        return None


class _Plan:
    """Per-stream constants: the plain stream's path, the regressors' recipe, the prior."""

    def __init__(self, comp: Compensator, adaptation: Adaptation,
                 rest_position: float | None, level: float | None = None) -> None:
        self.path = _Path(comp, rest_position, level)
        self.alpha = None if comp.band is None else 1.0 - (
            comp.band.level if level is None else level)
        self.adaptation = adaptation
        if adaptation.parameters == "weights":
            self.unit_params = _unit_weight_params(comp)
            scale = comp.scaling.position_scale
            self.contribution = scale * np.asarray(comp.params.w, dtype=np.float64)
            # estimate = sum_k c_k + constant, the constant from the bias and the centring
            self.constant = self.path.position_offset - scale * float(comp.params.v_b)
            n_mult = self.contribution.size
        else:
            self.constant = 0.0
            n_mult = 1
        span = (None if comp.position_range is None
                else comp.position_range[1] - comp.position_range[0])
        offset_std = adaptation.prior_offset or (0.1 * span if span else 1.0)
        multipliers = ("gain",) if n_mult == 1 else tuple(f"a_{k}" for k in range(n_mult))
        self.names = (*multipliers, "offset_mm")
        self.start = rls_start(np.r_[np.ones(n_mult), 0.0],
                               np.r_[np.full(n_mult, adaptation.prior_gain), offset_std])
        self.max_trace = float(np.trace(self.start.cov))
        self.plausible = Plausible.of(comp, self.path.position_offset, adaptation)

    def update(self, rls: RlsState, phi: np.ndarray, r: float) -> RlsState:
        """Learn one reference [mm] (``P`` bounded by the prior's trace: no wind-up while the
        references repeat one position)."""
        return rls_bound(rls_update(rls, phi, r - self.constant, self.adaptation.forgetting),
                         self.max_trace)

    def learn(self, state: AdaptiveState, phi: np.ndarray, r: float,
              estimate: float, half: float | None = None) -> AdaptiveState:
        """``state`` after the reference `r` [mm] of a sample estimated at `estimate` [mm]
        with band half-width `half` [mm] (None: no band): updated, or unchanged but for a
        count if `r` is implausible (rejected) or the update would leave the parameters'
        domain (refused). A plausible reference also moves the band's multiplier."""
        if self.plausible.why_not(r, estimate) is not None:
            return dataclasses.replace(state, n_rejected=state.n_rejected + 1)
        if half is not None:
            state = self.track_band(state, abs(r - estimate) > half)
        with np.errstate(all="ignore"):  # a non-finite result is refused just below
            rls = self.update(state.rls, phi, r)
        if not self.in_domain(rls.theta):
            return dataclasses.replace(state, n_refused=state.n_refused + 1)
        return dataclasses.replace(state, rls=rls)

    def track_band(self, state: AdaptiveState, miss: bool) -> AdaptiveState:
        """One step of the band's quantile tracking (module docstring)."""
        limit = float(np.log(MAX_BAND_FACTOR))
        log_factor = state.band_log_factor + BAND_STEP * (float(miss) - self.alpha)
        return dataclasses.replace(state, band_log_factor=min(max(log_factor, -limit), limit),
                                   n_band_misses=state.n_band_misses + int(miss),
                                   n_band_checks=state.n_band_checks + 1)

    @staticmethod
    def untouched(state: AdaptiveState) -> bool:
        """No reference has moved the output parameters or the band yet."""
        return state.rls.n_updates == 0 and state.n_band_checks == 0

    def half_width(self, state: AdaptiveState, plain_half: np.ndarray) -> np.ndarray:
        """The adapted band's half-width [mm] from the plain stream's."""
        gain = abs(float(state.rls.theta[0])) if self.adaptation.parameters == "gain" else 1.0
        return plain_half * (gain * float(np.exp(state.band_log_factor)))

    def in_domain(self, theta: np.ndarray) -> bool:
        """Whether output parameters ``theta`` lie in their domain (module docstring)."""
        if not np.all(np.isfinite(theta)) or abs(theta[-1]) > self.plausible.extent:
            return False
        multipliers = theta[:-1]
        if self.adaptation.parameters == "gain":
            return bool(1.0 / MAX_MULTIPLIER <= multipliers[0] <= MAX_MULTIPLIER)
        if not np.all(np.abs(multipliers) <= MAX_MULTIPLIER):
            return False
        comp = self.path.comp
        try:  # the weights and bias the update stands for, in the family's domain
            w = multipliers * np.asarray(comp.params.w, dtype=np.float64)
            v_b = float(comp.params.v_b) - theta[-1] / comp.scaling.position_scale
            dataclasses.replace(comp.params, w=w, v_b=v_b)
        except ValueError:
            return False
        return True

    def regressors(self, state: StreamState, sensor: np.ndarray,
                   estimate: np.ndarray) -> np.ndarray:
        """Regressors [mm], shape (n, p): the last column is the offset's (ones)."""
        ones = np.ones(sensor.size)
        if self.adaptation.parameters == "gain":
            return np.column_stack([estimate, ones])
        comp = self.path.comp
        # the normalised sensor exactly as _advance computes it (same operations, same bits)
        offset, _ = _sensor_offset(self.path, state, sensor)
        s = comp.polarity * (sensor - offset) / comp.scaling.sensor_scale
        x0 = None if state.x is None else np.array(state.x)
        cells = [comp.family.simulate(comp.structure, p, s, x0)[0] for p in self.unit_params]
        return np.column_stack([c * y for c, y in zip(self.contribution, cells, strict=True)]
                               + [ones])

    def predict(self, rls: RlsState, phi: np.ndarray, plain: np.ndarray) -> np.ndarray:
        """Estimates [mm] from ``theta``: the plain ones until the first reference."""
        if rls.n_updates == 0:
            return plain
        # a sum in a fixed order, element by element: a chunk gives the bits of single samples
        out = phi[:, 0] * rls.theta[0]
        for k in range(1, rls.theta.size):
            out = out + phi[:, k] * rls.theta[k]
        return out + self.constant


def _unit_weight_params(comp: Compensator) -> list[Any]:
    """The model's parameters with one output weight 1 and the others and the bias 0, after
    checking on a probe run that the output is linear in ``w`` and ``v_b``."""
    params = comp.params
    why = ""
    if comp.mode != "direct":
        why = "an inverse compensator's output is not linear in its weights"
    elif not (hasattr(params, "w") and hasattr(params, "v_b")):
        why = f"the {comp.model} model has no output weights w and bias v_b"
    if why:
        raise InputError(f"{comp.source or 'compensator'}: adaptation 'weights': {why}; "
                         f"use 'gain'")
    w = np.asarray(params.w, dtype=np.float64)
    try:
        units = [dataclasses.replace(params, w=np.eye(w.size)[k], v_b=0.0)
                 for k in range(w.size)]
    except ValueError as exc:  # the family's parameter checks refuse unit weights
        raise InputError(f"{comp.source or 'compensator'}: adaptation 'weights': the "
                         f"{comp.model} model cannot run one weight at a time ({exc}); "
                         f"use 'gain'") from None
    probe = np.sin(np.linspace(0.0, 6.0 * np.pi, 300)) * np.linspace(0.2, 1.0, 300)
    simulate = comp.family.simulate
    whole = simulate(comp.structure, params, probe)[0]
    parts = sum(wk * simulate(comp.structure, p, probe)[0] for wk, p in zip(w, units,
                                                                            strict=True))
    if not np.allclose(parts - params.v_b, whole, rtol=LINEARITY_TOLERANCE,
                       atol=LINEARITY_TOLERANCE * np.max(np.abs(whole))):
        raise InputError(f"{comp.source or 'compensator'}: adaptation 'weights': the "
                         f"{comp.model} model's output is not linear in w and v_b; use 'gain'")
    return units


def _references(reference: np.ndarray | None, n: int, first: int, label: str) -> np.ndarray:
    if reference is None:
        return np.full(n, np.nan)
    r = np.asarray(reference, dtype=np.float64).reshape(-1)
    if r.size != n:
        raise InputError(f"{label}: {r.size} references for {n} sensor samples")
    bad = np.flatnonzero(np.isinf(r))
    if bad.size:
        raise InputError(f"{label}: sample {first + bad[0]}: reference is infinite "
                         f"(NaN marks an unknown one)")
    return r


def _advance_plan(plan: _Plan, state: AdaptiveState, sensor: np.ndarray,
                  reference: np.ndarray | None,
                  label: str) -> tuple[StreamOutput, AdaptiveState]:
    s_raw = np.ascontiguousarray(sensor, dtype=np.float64).reshape(-1)
    r = _references(reference, s_raw.size, state.stream.n_samples, label)
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
        if compensator.center == "track":
            import scipy.signal  # noqa: F401  # now, not ~1 s late on the first sample

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
        r = _references(np.array([reference]), 1, self._state.stream.n_samples, self.label)[0]
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
