"""The stream's per-sample work as one compiled kernel: centring, the family's block, the
runaway guard, the use-time flags and the band, with the state held in arrays.

:class:`~._stream.Stream` runs a compensator through :class:`Engine` when the family's compiled
block (:meth:`hystkit.models.Family.block`, the closed loop's) reproduces the offline run bit for
bit, which :func:`Engine.build` checks on a probe signal for each compensator; otherwise, and for
every sample the kernel refuses (a runaway estimate, a sensor sample that normalises to no
finite number), the stream takes the readable Python path of :mod:`._readable`, which raises as
before. The arithmetic below repeats that path's operations in the same order, so both give the
same bits (tests: tests/live/test_stream_compiled.py).

A kernel is compiled once per block step (numba inlines the step, as the control loop does:
:func:`hystkit.control._kernel._kernel`) and cached on disk under the step's stable name.
"""

from __future__ import annotations

import numpy as np

from .._closure_cache import compile_closure
from .._kernel_inputs import read_only
from ..compensation import (
    MAX_NORMALISED,
    BandState,
    feature_decay,
    feature_range,
    feature_step,
    position_width,
)
from ..io import MAX_MAGNITUDE
from ._stream_state import StreamState

__all__ = ["Engine"]

CENTER_CODES = {"none": 0.0, "fit": 1.0, "tare": 2.0, "track": 3.0}
# consts: the compensator's per-sample numbers, by index
(C_CENTER, C_POLARITY, C_SENSOR_OFFSET, C_SENSOR_SCALE, C_SENSOR_REFERENCE, C_N_TARE,
 C_TRACK_GAIN, C_TRACK_DEN, C_POSITION_SCALE, C_POSITION_OFFSET, C_RUNAWAY, C_RUNAWAY_LO,
 C_RUNAWAY_HI, C_SENSOR_FLAG, C_SENSOR_LO, C_SENSOR_HI, C_ESTIMATE_FLAG, C_ESTIMATE_LO,
 C_ESTIMATE_HI, C_BAND, C_DT, C_DECAY, C_LOW, C_HIGH, C_QUANTILE, C_SHARE, C_RATE_REFERENCE,
 C_RATE_HIGH, C_POSITION_WIDTH, N_CONSTS) = range(30)
# mem: what the stream remembers besides the model state, by index
(M_N_SAMPLES, M_TARE_SUM, M_TRACK_VALUE, M_TRACK_WEIGHT, M_BAND_STARTED, M_BAND_PREVIOUS,
 M_BAND_RATE, M_BAND_OUTSIDE, N_MEM) = range(9)
# out: rows per sample
O_ESTIMATE, O_LOWER, O_UPPER, O_SENSOR_OUTSIDE, O_ESTIMATE_OUTSIDE = range(5)


def _make(step):
    """The kernel for one block step (a closure constant, inlined by numba).

    ``run(sensor, c, body, x, xn, mem, out)`` processes ``sensor`` until a sample is refused
    and returns how many it took; ``x`` and ``mem`` then hold the state after them (``xn`` is
    scratch of ``x``'s size), ``out[:, :taken]`` their results.
    """

    def run(sensor, c, body, x, xn, mem, out):
        center = c[C_CENTER]
        polarity, sensor_scale = c[C_POLARITY], c[C_SENSOR_SCALE]
        n_tare = c[C_N_TARE]
        gain, den = c[C_TRACK_GAIN], c[C_TRACK_DEN]
        band = c[C_BAND] != 0.0
        width = c[C_HIGH] - c[C_LOW]
        count = mem[M_N_SAMPLES]
        tare_sum, track_value, track_weight = mem[M_TARE_SUM], mem[M_TRACK_VALUE], \
            mem[M_TRACK_WEIGHT]
        started, previous = mem[M_BAND_STARTED], mem[M_BAND_PREVIOUS]
        rate, outside = mem[M_BAND_RATE], mem[M_BAND_OUTSIDE]
        a, b = x, xn
        swapped = False
        taken = 0
        for k in range(sensor.size):
            v = sensor[k]
            # the centring: _readable._advance_one's operations
            new_sum, new_value, new_weight = tare_sum, track_value, track_weight
            if center == 0.0:
                offset = 0.0
            elif center == 1.0:
                offset = c[C_SENSOR_OFFSET]
            else:
                if center == 2.0:
                    if count < n_tare:
                        new_sum = tare_sum + v
                        level = new_sum / (count + 1.0)
                    else:
                        level = tare_sum / n_tare
                else:  # track: one step of scipy's lfilter (transposed direct form II)
                    new_value = -(den * track_value) + gain * v
                    new_weight = -(den * track_weight) + gain * 1.0
                    level = new_value / new_weight
                offset = c[C_SENSOR_OFFSET] + level - c[C_SENSOR_REFERENCE]
            s = polarity * (v - offset) / sensor_scale
            if not np.isfinite(s):
                break  # the family refuses it: the Python path says how
            for i in range(a.size):
                b[i] = a[i]
            p = step(body, a, b, 0, s)
            estimate = p * c[C_POSITION_SCALE] + c[C_POSITION_OFFSET]
            # Compensator.runaway_samples (NaN fails every comparison)
            if not (abs(p) <= MAX_NORMALISED and abs(estimate) <= MAX_MAGNITUDE):
                break
            if c[C_RUNAWAY] != 0.0 and not (estimate >= c[C_RUNAWAY_LO]
                                            and estimate <= c[C_RUNAWAY_HI]):
                break
            a, b = b, a
            swapped = not swapped
            tare_sum, track_value, track_weight = new_sum, new_value, new_weight
            out[O_ESTIMATE, k] = estimate
            if c[C_SENSOR_FLAG] != 0.0:
                out[O_SENSOR_OUTSIDE, k] = 1.0 if (s < c[C_SENSOR_LO]
                                                   or s > c[C_SENSOR_HI]) else 0.0
            if c[C_ESTIMATE_FLAG] != 0.0:
                out[O_ESTIMATE_OUTSIDE, k] = 1.0 if (estimate < c[C_ESTIMATE_LO]
                                                     or estimate > c[C_ESTIMATE_HI]) else 0.0
            if band:
                rate, outside = feature_step(s, started, previous, rate, outside, c[C_DT],
                                             c[C_DECAY], c[C_LOW], c[C_HIGH], width)
                previous = s
                started = 1.0
                # _band.half_width: quantile * rate_scale + position_width * outside
                over = rate / c[C_RATE_HIGH] - 1.0
                over = np.maximum(over, 0.0)  # as _band.rate_scale (NaN stays NaN)
                sigma = 1.0 - c[C_SHARE] + c[C_SHARE] * rate / c[C_RATE_REFERENCE] + over
                half = c[C_QUANTILE] * sigma + c[C_POSITION_WIDTH] * outside
                out[O_LOWER, k] = estimate - half
                out[O_UPPER, k] = estimate + half
            count += 1.0
            taken = k + 1
        if swapped:
            for i in range(x.size):
                x[i] = xn[i]
        mem[M_N_SAMPLES] = count
        mem[M_TARE_SUM], mem[M_TRACK_VALUE], mem[M_TRACK_WEIGHT] = tare_sum, track_value, \
            track_weight
        mem[M_BAND_STARTED], mem[M_BAND_PREVIOUS] = started, previous
        mem[M_BAND_RATE], mem[M_BAND_OUTSIDE] = rate, outside
        return taken

    return run


_COMPILED: dict = {}


def kernel(step):
    """The compiled kernel for block step `step`, cached on disk when the step has a stable
    name (as the control loop's, whose cache machinery it shares)."""
    if step not in _COMPILED:
        # keyed by this file's band step too: numba's own key would pickle the step
        _COMPILED[step] = compile_closure(_make(step), (step, feature_step))
    return _COMPILED[step]



class Engine:
    """A compensator's stream in arrays: constants, block, model state, memory, buffers.

    Parameters
    ----------
    path : _readable._Path
        The compensator's per-sample constants.
    """

    def __init__(self, path) -> None:
        comp = path.comp
        block = comp.family.block(comp.structure, comp.params, comp.mode == "inverse")
        self.run_kernel = kernel(block.step)
        self.body = np.ascontiguousarray(block.body, dtype=np.float64)
        self.x = np.zeros(block.n_state)
        self.xn = np.zeros(block.n_state)
        self.mem = np.zeros(N_MEM)
        self.consts = _constants(path)
        self._one = np.zeros(1)
        self._one_read = read_only(self._one)  # what the kernel reads: `run`'s type
        self._one_out = np.zeros((5, 1))

    def load(self, state) -> None:
        """Take `state` (a :class:`~._stream_state.StreamState` with a model state) as the present."""
        self.x[:] = state.x
        band = state.band
        self.mem[:] = (state.n_samples, state.tare_sum, state.track_value, state.track_weight,
                       float(band.started), band.previous, band.rate, band.outside)

    def state(self):
        """The present state as a :class:`~._stream_state.StreamState`."""

        m = self.mem.tolist()
        return StreamState(self.x.copy(), int(m[M_N_SAMPLES]), m[M_TARE_SUM], m[M_TRACK_VALUE],
                           m[M_TRACK_WEIGHT], BandState(bool(m[M_BAND_STARTED]),
                                                        m[M_BAND_PREVIOUS], m[M_BAND_RATE],
                                                        m[M_BAND_OUTSIDE]))

    def run(self, sensor: np.ndarray) -> tuple[np.ndarray, int]:
        """Samples of `sensor` (contiguous float64) until one is refused: the rows of
        ``out`` (estimate, lower, upper, sensor and estimate outside as 0/1) and how many were
        taken; the state advances over those."""
        out = np.zeros((5, sensor.size))
        taken = self.run_kernel(read_only(sensor), self.consts, self.body, self.x, self.xn, self.mem, out)
        return out, taken

    def step(self, value: float) -> list[float] | None:
        """One sample: its column of ``out`` as a list, None if refused (state unchanged)."""
        self._one[0] = value
        out = self._one_out
        if not self.run_kernel(self._one_read, self.consts, self.body, self.x, self.xn, self.mem,
                               out):
            return None
        return out[:, 0].tolist()


def _constants(path) -> np.ndarray:
    """The kernel's ``consts`` from a stream's `_Path` (the same numbers its Python path
    uses)."""
    comp = path.comp
    c = np.zeros(N_CONSTS)
    c[C_CENTER] = CENTER_CODES[comp.center]
    c[C_POLARITY] = comp.polarity
    c[C_SENSOR_OFFSET] = comp.scaling.sensor_offset
    c[C_SENSOR_SCALE] = comp.scaling.sensor_scale
    c[C_SENSOR_REFERENCE] = comp.sensor_reference
    c[C_N_TARE] = path.n_tare
    c[C_TRACK_GAIN] = path.track_gain
    c[C_TRACK_DEN] = path.track_gain - 1.0
    c[C_POSITION_SCALE] = comp.scaling.position_scale
    c[C_POSITION_OFFSET] = path.position_offset
    for flag, lo, bounds in ((C_RUNAWAY, C_RUNAWAY_LO, path.runaway_bounds),
                             (C_SENSOR_FLAG, C_SENSOR_LO, path.sensor_bounds),
                             (C_ESTIMATE_FLAG, C_ESTIMATE_LO, path.estimate_bounds)):
        if bounds is not None:
            c[flag], c[lo], c[lo + 1] = 1.0, bounds[0], bounds[1]
    band = comp.band
    if band is not None:
        c[C_BAND] = 1.0
        c[C_DT] = comp.structure.dt
        c[C_DECAY] = feature_decay(comp.structure.dt, band.tau)
        c[C_LOW], c[C_HIGH] = feature_range(comp.training_range)
        c[C_QUANTILE] = path.band_quantile
        c[C_SHARE], c[C_RATE_REFERENCE] = band.rate_share, band.rate_reference
        c[C_RATE_HIGH] = band.rate_high
        c[C_POSITION_WIDTH] = position_width(comp)
    return c
