"""Whether a compensator's stream may run compiled: the kernel (:mod:`._stream_kernel`)
against the readable path (:mod:`._readable`) on a probe signal, bit for bit (estimates, flags,
band, end state)."""

from __future__ import annotations

import numpy as np

from ..compensation import Compensator
from ..errors import FitDivergedError
from ._readable import _advance, _Path
from ._stream_kernel import Engine
from ._stream_output import _chunk_output, _concatenate
from ._stream_state import StreamState

__all__ = ["compiled_engine"]

# Samples of the signal on which a stream checks its compiled kernel against the Python path.
PROBE_SAMPLES = 256


def compiled_engine(path: _Path):
    """The compiled kernel's engine for `path` (:mod:`._stream_kernel`), or None when the
    family has no compiled block or its block does not give the Python path's bits on a probe
    signal (then every sample takes the Python path)."""
    try:
        engine = Engine(path)
    except NotImplementedError:  # a family without a block
        return None
    return engine if _reproduces(engine, path) else None


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
