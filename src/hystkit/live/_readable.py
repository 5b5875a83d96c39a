"""The readable stream: :func:`advance`, a chunk of raw sensor samples from a
:class:`StreamState` in numpy around the family's compiled ``simulate`` / ``invert``, and
:func:`_advance_one`, one sample in Python floats with the same operations (so the same bits).

These are the reference of the compiled kernel (:mod:`._stream_kernel`), which
:class:`~._stream.Stream` runs when the kernel gives their bits on a probe signal
(:mod:`._stream_probe`); they run a stream's first sample at rest, a sample the kernel
refuses, and every sample of a family whose kernel does not give their bits.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ..compensation import (
    MAX_NORMALISED,
    ORACLE_CENTER,
    POSITION_MARGIN,
    SENSOR_MARGIN,
    BandState,
    Compensator,
    band_features,
    half_width,
    position_width,
    runaway_kind,
    runaway_samples,
)
from ..errors import FitDivergedError, InputError
from ..io import MAX_MAGNITUDE
from ._stream_output import StepOutput, StreamOutput, _flags
from ._stream_state import StreamState
from ._sync import sync_excitation

__all__ = ["StartUp", "advance", "advance_scaled", "check_streamable", "initial_state"]

StartUp = str | np.ndarray


@dataclass(frozen=True, eq=False)
class _Path:
    """The compensator's per-sample constants, derived once, with the same operations as
    ``Compensator`` and ``_centring.sensor_level`` (so that both give the same bits)."""

    comp: Compensator
    rest_position: float | None
    level: float | None = None
    n_tare: int = field(init=False)
    track_gain: float = field(init=False)
    position_offset: float = field(init=False)
    sensor_bounds: tuple[float, float] | None = field(init=False)
    estimate_bounds: tuple[float, float] | None = field(init=False)
    runaway_bounds: tuple[float, float] | None = field(init=False)
    band_quantile: float | None = field(init=False)

    def __post_init__(self) -> None:
        comp, dt = self.comp, self.comp.structure.dt
        values = {"n_tare": max(1, round(comp.tare_seconds / dt)),
                  "track_gain": float(1.0 - np.exp(-dt / comp.track_seconds)),
                  "position_offset": comp.position_offset(None, self.rest_position),
                  "sensor_bounds": None, "estimate_bounds": None,
                  "band_quantile": None if comp.band is None else comp.band.quantile(self.level)}
        values["runaway_bounds"] = comp.runaway_bounds(values["position_offset"])
        # Compensator.sensor_outside / estimate_outside: outside [lo - pad, hi + pad]
        if comp.training_range is not None:
            lo, hi = comp.training_range
            pad = SENSOR_MARGIN * (hi - lo)
            values["sensor_bounds"] = (lo - pad, hi + pad)
        if comp.position_range is not None:
            lo, hi = comp.position_range
            pad = POSITION_MARGIN * (hi - lo)
            offset = comp.position_offset() - comp.scaling.position_offset
            values["estimate_bounds"] = (lo + offset - pad, hi + offset + pad)
        for name, value in values.items():
            object.__setattr__(self, name, value)


def check_streamable(comp: Compensator) -> None:
    """Refuse a compensator that cannot run causally (the oracle centring), or that may not
    be run live: a model without the stability limit (``--no-limit``), whose divergence a
    sample-by-sample run could only see once its estimates were already wrong."""
    if comp.center == ORACLE_CENTER:
        raise InputError(
            f"{comp.source or 'compensator'}: key 'center': 'recording' (oracle) removes the "
            f"whole recording's sensor mean, which a stream does not know until it ends; refit "
            f"with --center fit, tare or track")
    if getattr(comp.structure, "limit", True) is False:
        raise InputError(
            f"{comp.source or 'compensator'}: key 'structure.limit': false (fitted with "
            f"--no-limit, for study): without the stability limit (eq. 5.29) the model can "
            f"diverge (sec. 5.3.3), so it is not run live; refit without --no-limit")


def initial_state(comp: Compensator, start: StartUp = "rest") -> StreamState:
    """The state a stream starts from: ``"rest"``, ``"sync"`` (eq. 2.21-2.22) or a model
    state vector (its length is the family's state size).

    Parameters
    ----------
    comp : Compensator
        The compensator the stream runs.
    start : "rest", "sync" or array, default "rest"
        Start-up: ``"rest"``: the model at rest at the first sample (what ``estimate``
        does); ``"sync"``: the state left by the synchronisation excitation (eq. 2.21-2.22,
        :func:`sync_excitation`), once the device has been driven through it; an array: a
        given model state (its length is the family's state size), e.g. one saved from an
        earlier run.

    Returns
    -------
    StreamState
        No samples seen; the model state of ``start`` (None for ``"rest"``).

    Raises
    ------
    InputError
        If ``comp`` uses the oracle centring, ``start`` is another string, or a state vector
        has the wrong size or a non-finite value.
    """
    check_streamable(comp)
    if isinstance(start, str):
        if start == "rest":
            return StreamState(None)
        if start == "sync":
            return StreamState(sync_excitation(comp).state_after)
        raise InputError(f"start {start!r}: use 'rest', 'sync' or a model state vector")
    x = np.asarray(start, dtype=np.float64)
    size = _state_size(comp)
    if x.shape != (size,) or not np.all(np.isfinite(x)):
        raise InputError(f"start state: the {comp.model} {'inverse ' * (comp.mode == 'inverse')}"
                         f"model needs {size} finite numbers, got shape {x.shape}")
    return StreamState(x)


def _state_size(comp: Compensator) -> int:
    rest = comp.family.rest_state(comp.structure, comp.params, 0.0, comp.mode == "inverse")
    return int(np.asarray(rest).size)


def advance(comp: Compensator, state: StreamState, sensor: np.ndarray, *,
            rest_position: float | None = None, label: str = "stream",
            level: float | None = None) -> tuple[StreamOutput, StreamState]:
    """Run one chunk of raw sensor samples [sensor units] from ``state``.

    Pure: nothing is kept anywhere; the returned state continues the stream.

    Parameters
    ----------
    comp : Compensator
        The compensator; not one with the oracle centring ``recording``, which a stream
        cannot run (:func:`initial_state` refuses it).
    state : StreamState
        Where the stream is: :func:`initial_state` for a new one, else the state returned by
        the previous call.
    sensor : numpy.ndarray, shape (n,)
        The chunk's raw sensor samples [sensor units]; may be empty.
    rest_position : float, optional
        Where the device rests during the tare window [mm], if not where it rested in
        training (``tare`` only; as :meth:`Compensator.estimate`).
    label : str, default "stream"
        Names the stream in error messages.
    level : float, optional
        Nominal coverage of the band in the output; default the band's own.

    Returns
    -------
    output : StreamOutput
        The chunk's estimates [mm], their band and the use-time flags.
    state : StreamState
        The state after the chunk's last sample.

    Raises
    ------
    FitDivergedError
        If an estimate is not finite or beyond ``MAX_NORMALISED`` times the training
        positions (as :meth:`Compensator.estimate`); the message names ``label`` and the
        stream's sample index. ``state`` is unchanged then.
    InputError
        If ``comp`` has the oracle centring ``recording``.
    """
    check_streamable(comp)  # a state made for another compensator must not smuggle one in
    return _advance(_Path(comp, rest_position, level), state, sensor, label)


def _advance(path: _Path, state: StreamState, sensor: np.ndarray,
             label: str) -> tuple[StreamOutput, StreamState]:
    out, nxt, _ = advance_scaled(path, state, sensor, label)
    return out, nxt


def advance_scaled(path: _Path, state: StreamState, sensor: np.ndarray,
                   label: str) -> tuple[StreamOutput, StreamState, np.ndarray]:
    """`_advance`, and the centred, scaled sensor the model ran on (what a window re-fit on
    the stream's own input needs, without centring the part a second time)."""
    comp = path.comp
    s_raw = np.ascontiguousarray(sensor, dtype=np.float64).reshape(-1)
    if s_raw.size == 0:
        empty = np.empty(0)
        band = (None, None) if comp.band is None else (empty, empty)
        return StreamOutput(empty, *_flags(path, empty, empty), *band), state, empty
    offset, centring = _sensor_offset(path, state, s_raw)
    s = comp.polarity * (s_raw - offset) / comp.scaling.sensor_scale
    half, centring["band"] = _half_width(path, s, state.band)
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            p, x_end = _run_model(comp, s, state.x)
        except FitDivergedError as exc:
            first, last = state.n_samples, state.n_samples + s.size - 1
            where = f"sample {first}" if first == last else f"samples {first}-{last}"
            raise FitDivergedError(f"{label}: {where}: the {comp.model} compensator"
                                   f"{_of(comp)}: {exc}") from None
        estimate = p * comp.scaling.position_scale + path.position_offset
    _check_runaway(path, p, estimate, state.n_samples, label)
    nxt = StreamState(x_end, state.n_samples + s.size, **centring)
    band = (None, None) if half is None else (estimate - half, estimate + half)
    return StreamOutput(estimate, *_flags(path, s, estimate), *band), nxt, s


def _half_width(path: _Path, s: np.ndarray,
                state: BandState) -> tuple[np.ndarray | None, BandState]:
    """The band's half-width [mm] over a chunk of scaled sensor samples, continuing the
    features from `state` (``compensation.band_features``; the same operations as
    ``compensation.interval``, so chunked == whole); None without a band."""
    comp = path.comp
    if comp.band is None:
        return None, state
    rate, outside, nxt = band_features(s, comp.structure.dt, comp.band.tau, comp.training_range,
                                       state)
    return half_width(comp.band, path.band_quantile, rate, outside, position_width(comp)), nxt


def _run_model(comp: Compensator, s: np.ndarray,
               x: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The family's compiled run from ``x`` (None: at rest at ``s[0]``, as ``estimate``)."""
    x0 = None if x is None else np.array(x)
    if comp.mode == "inverse":
        return comp.family.invert(comp.structure, comp.params, s, x0)
    p, x_end = comp.family.simulate(comp.structure, comp.params, s, x0)
    if s.size == 1:
        # A family whose output is ``states @ weights`` (bobbio) gets numpy's
        # single-row matmul here, which sums in another order than the many-row one of a
        # whole run: take the output of a two-sample run (the sample repeated) instead.
        try:
            p = comp.family.simulate(comp.structure, comp.params, np.repeat(s, 2), x0)[0][:1]
        except FitDivergedError:  # the repeated sample ran away: keep the one-sample output
            pass
    return p, x_end


def _sensor_offset(path: _Path, state: StreamState,
                   s: np.ndarray) -> tuple[np.ndarray | float, dict]:
    """Offset per sample and the centring's next state, continuing ``_centring.sensor_level``
    with the same floating-point operations in the same order (so chunked == whole)."""
    comp = path.comp
    kept = {"tare_sum": state.tare_sum, "track_value": state.track_value,
            "track_weight": state.track_weight}
    if comp.center == "none":
        return 0.0, kept
    if comp.center == "fit":
        return comp.scaling.sensor_offset, kept
    if comp.center == "tare":
        level, kept["tare_sum"] = _tare_level(path.n_tare, state, s)
    else:  # track: _centring.sensor_level's two low-passes, continued from the stored outputs
        value = _low_pass(path.track_gain, s.tolist(), state.track_value)
        weight = _low_pass(path.track_gain, [1.0] * s.size, state.track_weight)
        kept["track_value"], kept["track_weight"] = float(value[-1]), float(weight[-1])
        level = value / weight
    return comp.scaling.sensor_offset + level - comp.sensor_reference, kept


def _low_pass(gain: float, x: list[float], last: float) -> np.ndarray:
    """``scipy.signal.lfilter([gain], [1, gain - 1], x, zi=[-(gain - 1) * last])``, the
    offline tracker's filter continued after its output `last`, with lfilter's operations in
    its order (transposed direct form II: ``y = z + b0 x``, ``z = b1 x - a1 y``, ``b1 = 0``):
    the same bits, without importing scipy.signal (~0.7 s of a stream's start)."""
    den = gain - 1.0
    z = -(den * last)
    out = []
    for v in x:
        y = z + gain * v
        z = v * 0.0 - y * den
        out.append(y)
    return np.array(out)


def _tare_level(n_tare: int, state: StreamState, s: np.ndarray) -> tuple[np.ndarray, float]:
    """Running mean inside the tare window, its final mean after it."""
    start = state.n_samples
    n_in = max(0, min(n_tare - start, s.size))
    total = state.tare_sum
    level = np.empty(s.size)
    if n_in:
        # cumsum adds in order, so continuing from the stored sum repeats the whole run's sums
        sums = np.cumsum(np.concatenate([[total], s[:n_in]]))[1:]
        level[:n_in] = sums / np.arange(start + 1, start + n_in + 1)
        total = float(sums[-1])
    if n_in < s.size:
        level[n_in:] = total / n_tare
    return level, total


def _check_runaway(path: _Path, p: np.ndarray, estimate: np.ndarray, first: int,
                   label: str) -> None:
    # The guard of Compensator.estimate, after de-normalisation as there.
    comp = path.comp
    bad = runaway_samples(p, estimate, path.runaway_bounds)
    if bad.size:
        raise FitDivergedError(f"{label}: sample {first + bad[0]}: the {comp.model} "
                               f"compensator{_of(comp)} gives an estimate that is "
                               f"{runaway_kind(estimate[bad[0]])}")


class _Previous(NamedTuple):
    """What a direct stream's last one-sample step started from: lets the next step run the
    last two samples in one compiled call (see :func:`_run_model`) instead of two. A cache,
    not memory: valid only for the exact ``after`` state it was made with, and the result is
    the same bits with or without it."""

    after: StreamState
    x: np.ndarray | None
    s: float


def _advance_one(path: _Path, state: StreamState, v: float, label: str,
                 previous: _Previous | None = None
                 ) -> tuple[StepOutput, StreamState, _Previous]:
    """:func:`_advance` for one sample, in Python floats (the same operations, so the same
    bits) around the family's compiled run: a fraction of the array path's overhead."""
    comp = path.comp
    v = float(v)
    tare_sum, track_value, track_weight = state.tare_sum, state.track_value, state.track_weight
    if comp.center in ("fit", "none"):
        offset = comp.scaling.sensor_offset if comp.center == "fit" else 0.0
    else:
        if comp.center == "tare":
            if state.n_samples < path.n_tare:
                tare_sum = tare_sum + v
                level = tare_sum / (state.n_samples + 1)
            else:
                level = tare_sum / path.n_tare
        else:  # track: scipy's lfilter, one step of its transposed direct form II
            den = path.track_gain - 1.0
            track_value = -(den * track_value) + path.track_gain * v
            track_weight = -(den * track_weight) + path.track_gain * 1.0
            level = track_value / track_weight
        offset = comp.scaling.sensor_offset + level - comp.sensor_reference
    s = comp.polarity * (v - offset) / comp.scaling.sensor_scale
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            if comp.mode == "direct" and previous is not None and previous.after is state:
                # the last two samples from the state before the last: output and state at once
                p_run, x_end = comp.family.simulate(comp.structure, comp.params,
                                                    np.array([previous.s, s]),
                                                    None if previous.x is None
                                                    else np.array(previous.x))
                p_run = p_run[1:]
            else:
                p_run, x_end = _run_model(comp, np.array([s]), state.x)
        except FitDivergedError as exc:
            raise FitDivergedError(f"{label}: sample {state.n_samples}: the {comp.model} "
                                   f"compensator{_of(comp)}: {exc}") from None
    p = float(p_run[0])
    estimate = p * comp.scaling.position_scale + path.position_offset
    bounds = path.runaway_bounds
    if not (abs(p) <= MAX_NORMALISED and abs(estimate) <= MAX_MAGNITUDE
            and (bounds is None or bounds[0] <= estimate <= bounds[1])):
        _check_runaway(path, np.array([p]), np.array([estimate]), state.n_samples, label)
    half, band_state = _half_width(path, np.array([s]), state.band)
    band = (None, None) if half is None else (estimate - float(half[0]),
                                              estimate + float(half[0]))
    nxt = StreamState(x_end, state.n_samples + 1, tare_sum, track_value, track_weight,
                      band_state)
    return (StepOutput(estimate, *_flags(path, s, estimate), *band), nxt,
            _Previous(nxt, state.x, s))


def _of(comp: Compensator) -> str:
    return "" if comp.source is None else f" of {comp.source}"
