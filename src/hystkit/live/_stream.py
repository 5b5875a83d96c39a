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

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..compensation import ORACLE_CENTER
from ..compensation._band import BandState, band_features, half_width, position_width
from ..compensation._compensator import (
    MAX_NORMALISED,
    POSITION_MARGIN,
    SENSOR_MARGIN,
    Compensator,
    runaway_kind,
    runaway_samples,
)
from ..errors import FitDivergedError, InputError
from ..io import MAX_MAGNITUDE
from ._stream_kernel import Engine
from ._stream_state import StreamState
from ._sync import sync_excitation

__all__ = ["StartUp", "StepOutput", "Stream", "StreamOutput", "StreamState", "advance",
           "initial_state"]

StartUp = str | np.ndarray
# Samples of the signal on which a stream checks its compiled kernel against the Python path.
PROBE_SAMPLES = 256


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
    features from `state` (:func:`._band.band_features`; the same operations as
    :func:`._band.interval`, so chunked == whole); None without a band."""
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
        # A family whose output is ``states @ weights`` (ladder, bobbio) gets numpy's
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
    else:  # track
        a = path.track_gain
        b, den = [a], [1.0, a - 1.0]
        from scipy.signal import lfilter  # here: scipy.signal costs ~0.7 s to import

        # lfilter's delay after an output y is -(a - 1) y: continue from the stored outputs.
        value, _ = lfilter(b, den, s, zi=[-(den[1] * state.track_value)])
        weight, _ = lfilter(b, den, np.ones_like(s), zi=[-(den[1] * state.track_weight)])
        kept["track_value"], kept["track_weight"] = float(value[-1]), float(weight[-1])
        level = value / weight
    return comp.scaling.sensor_offset + level - comp.sensor_reference, kept


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


def _flags(path: _Path, s: np.ndarray | float,
           estimate: np.ndarray | float) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Masks (or booleans, for scalars) of ``Compensator.sensor_outside`` / ``estimate_outside``."""
    return _outside(s, path.sensor_bounds), _outside(estimate, path.estimate_bounds)


def _outside(values, bounds: tuple[float, float] | None):
    if bounds is None:
        return None
    return (values < bounds[0]) | (values > bounds[1])


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


def compiled_engine(path: _Path):
    """The compiled kernel's engine for `path` (:mod:`._stream_kernel`), or None when the
    family has no compiled block or its block does not give the Python path's bits on a probe
    signal (then every sample takes the Python path)."""

    try:
        engine = Engine(path)
    except NotImplementedError:  # a family without a block
        return None
    if path.comp.center != "track":
        return engine if _reproduces(engine, path) else None
    # The family's block is what the probe checks; the tracker is the same code for every
    # family (tested), and its Python path would import scipy.signal (~0.7 s).
    probed = _Path(dataclasses.replace(path.comp, center="fit"), path.rest_position,
                   path.level)
    return engine if _reproduces(Engine(probed), probed) else None


def _reproduces(engine, path: _Path) -> bool:
    """Whether `engine` gives the Python path's bits (estimates, flags, band, end state) on
    the probe signal, from a stream at rest (its first sample by the Python path)."""
    probe = _probe(path.comp)
    start = StreamState(None)
    try:
        with np.errstate(all="ignore"):
            want, want_state = _advance(path, start, probe, "probe")
            first, state = _advance(path, start, probe[:1], "probe")
    except (FitDivergedError, ValueError):  # the probe ran away: nothing to compare with
        return False
    engine.load(state)
    rows, taken = engine.run(probe[1:])
    if taken != probe.size - 1:
        return False
    got = _concatenate(path, [first, _chunk_output(path, rows)])
    return all(_same_bits(a, b) for a, b in zip(got, want, strict=True)) and \
        _same_state(engine.state(), want_state)


def _probe(comp: Compensator) -> np.ndarray:
    """Raw sensor samples that drive the model through the training range and 30 % beyond
    it (an inverse: through its forward model's outputs), growing and shrinking swings."""
    n = np.arange(PROBE_SAMPLES)
    swing = np.sin(2 * np.pi * n / 61.0) * (0.3 + np.abs(np.sin(2 * np.pi * n / 173.0)))
    lo, hi = comp.training_range if comp.training_range is not None else (-1.0, 1.0)
    s = 0.5 * (lo + hi) + 0.5 * (hi - lo) * swing  # up to 1.3 half-ranges from the middle
    if comp.mode == "inverse":
        try:
            with np.errstate(all="ignore"):
                s, _ = comp.family.simulate(comp.structure, comp.params, s / 1.3)
        except (FitDivergedError, ValueError):
            pass  # the forward run failed: probe the inverse with the swing itself
    return comp.scaling.sensor_offset + s * comp.scaling.sensor_scale / comp.polarity


def _same_bits(a, b) -> bool:
    if a is None or b is None:
        return a is b
    return bool(np.array_equal(a, b))


def _same_state(a: StreamState, b: StreamState) -> bool:
    return (np.array_equal(a.x, b.x) and a.n_samples == b.n_samples
            and (a.tare_sum, a.track_value, a.track_weight) == (b.tare_sum, b.track_value,
                                                                b.track_weight)
            and a.band == b.band)


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


def _of(comp: Compensator) -> str:
    return "" if comp.source is None else f" of {comp.source}"


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
        from ..compensation import load_compensator
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
