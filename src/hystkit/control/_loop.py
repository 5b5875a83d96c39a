"""Closed position loop with a hysteretic sensor (ch. 7): configuration and state.

Schemes (both with the optional disturbance observer of sec. 7.4):

- ``direct`` (a), fig. 7.1: ``e = r - y_hat`` with ``y_hat = compensator(s)``, ``s = S_r(y)``;
- ``weighting`` (b), fig. 7.8: ``e = g_s (S_m(r) - s)``; ``g_s`` [m per sensor unit] is a fixed
  straight-line calibration so the PID sees metres in both schemes. The plant estimate of
  fig. 7.11 (nominal plant driven by the applied force) is recorded in every run.

A :class:`ControlLoop` is what defines a loop, a :class:`LoopState` the memory of its blocks
(explicit, in and out: a run split in two equals the whole run); running it: ``_simulate.py``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from . import _kernel
from ._blocks import PID, TS, DisturbanceObserver, Plant, plant_matrices
from ._names import SCHEMES
from ._sensor_blocks import SensorBlock

__all__ = ["SCHEMES", "ControlLoop", "LoopState", "rest_state", "tare"]


@dataclass(frozen=True, eq=False)
class ControlLoop:
    """Everything that defines a loop; no state (that is :class:`LoopState`).

    Parameters
    ----------
    scheme : {"direct", "weighting"}
    sensor : SensorBlock
        ``S_r``: position [m] -> sensor signal.
    pid : PID
    plant : Plant
    compensator : SensorBlock, optional
        Sensor -> position estimate [m]. Needed by ``direct`` and by the DOB; with
        ``weighting`` it only produces the estimate ``y_hat`` (fig. 7.10, 7.15).
    model : SensorBlock, optional
        ``S_m``: position [m] -> sensor; needed by ``weighting``.
    sensor_gain : float
        ``g_s`` [m per sensor unit] of scheme (b).
    dob : DisturbanceObserver, optional
    nominal_mass : float, optional
        Mass [kg] of the plant model in the estimate (fig. 7.11) and the DOB; default the
        plant's own (the document's ideal case).
    ts : float
        Sample time [s] (sec. 7.2).
    y_limit : float
        A plant position beyond this [m] counts as unbounded and stops the run.
    """

    scheme: str
    sensor: SensorBlock
    pid: PID
    plant: Plant = field(default_factory=Plant)
    compensator: SensorBlock | None = None
    model: SensorBlock | None = None
    sensor_gain: float = 1.0
    dob: DisturbanceObserver | None = None
    nominal_mass: float | None = None
    ts: float = TS
    y_limit: float = 1.0

    def __post_init__(self) -> None:
        if self.scheme not in SCHEMES:
            raise ValueError(f"scheme must be one of {SCHEMES}, got {self.scheme!r}")
        if self.scheme == "direct" and self.compensator is None:
            raise ValueError("scheme 'direct' needs a compensator (fig. 7.1)")
        if self.scheme == "weighting" and self.model is None:
            raise ValueError("scheme 'weighting' needs a model S_m (fig. 7.8)")
        if self.dob is not None and self.compensator is None:
            raise ValueError("the disturbance observer needs the compensator's position "
                             "estimate (fig. 7.18-7.19)")
        if self.compensator is not None and self.compensator is self.sensor:
            raise ValueError("sensor and compensator are one object")
        if self.model is not None and self.model is self.sensor:
            raise ValueError("S_r and S_m are one object: identical models make an "
                             "unrealistic identity (sec. 6.2.2)")
        if not (np.isfinite(self.sensor_gain) and self.sensor_gain != 0):
            raise ValueError(f"sensor_gain must be finite and non-zero, got {self.sensor_gain}")
        if not (np.isfinite(self.ts) and self.ts > 0 and self.y_limit > 0):
            raise ValueError("ts and y_limit must be positive")

    @property
    def mass_n(self) -> float:
        """Nominal mass used by the plant estimate and the DOB [kg]."""
        return self.plant.mass if self.nominal_mass is None else self.nominal_mass

    def sizes(self) -> tuple[int, int, int]:
        """State lengths of S_r, compensator, S_m (0 if absent)."""
        return (self.sensor.n_state,
                0 if self.compensator is None else self.compensator.n_state,
                0 if self.model is None else self.model.n_state)

    def kernel_arguments(self) -> tuple:
        """Packed constant arguments of :func:`_kernel.run` after ``x0``."""
        _, b, _ = plant_matrices(self.plant.mass, self.ts)
        _, b_n, _ = plant_matrices(self.mass_n, self.ts)
        plant = np.array([self.ts, b[0], b[1], b_n[0], b_n[1], self.plant.u_max])
        p = self.pid
        pid = np.array([p.kp, self.ts / p.ti if np.isfinite(p.ti) else 0.0, p.td, p.tf,
                        float(p.anti_windup), self.sensor_gain])
        dob = (np.zeros(4) if self.dob is None
               else np.r_[1.0, self.dob.observer_gain(self.mass_n, self.ts)])
        absent = (_kernel.identity_step, np.array([1.0, 0.0, 1.0, 0.0]), np.empty(0))
        slots = [self.sensor.pack(self.ts),
                 absent if self.compensator is None else self.compensator.pack(self.ts),
                 absent if self.model is None else self.model.pack(self.ts)]
        sizes = np.array([*self.sizes(), self.compensator is not None, self.model is not None],
                         dtype=np.int64)
        return (self.scheme == "direct", plant, pid, dob, float(self.y_limit), sizes,
                *(item for slot in slots for item in slot))


@dataclass(frozen=True, eq=False)
class LoopState:
    """Memory of every block; what a run needs to continue exactly where another stopped.

    Parameters
    ----------
    plant : array_like, shape (2,)
        Position [m], velocity [m/s].
    pid : array_like, shape (3,)
        Integral term, previous error, derivative term (eq. 7.2).
    estimate : array_like, shape (2,)
        Nominal-plant position [m] and velocity [m/s] (fig. 7.11).
    dob : array_like, shape (3,)
        Observer estimates of position [m], velocity [m/s], input force [N].
    sensor, compensator, model : array_like
        States of S_r, compensator, S_m (normalised units; empty for an absent block).

    Raises
    ------
    ValueError
        If a value is not finite.
    """

    plant: np.ndarray
    pid: np.ndarray
    estimate: np.ndarray
    dob: np.ndarray
    sensor: np.ndarray
    compensator: np.ndarray
    model: np.ndarray

    def __post_init__(self) -> None:
        for name in ("plant", "pid", "estimate", "dob", "sensor", "compensator", "model"):
            arr = np.array(getattr(self, name), dtype=float).reshape(-1)
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"state {name} must be finite")
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    def to_vector(self) -> np.ndarray:
        """Every block's state, concatenated in the order of the fields (the kernel's)."""
        return np.concatenate([self.plant, self.pid, self.estimate, self.dob, self.sensor,
                               self.compensator, self.model])

    @classmethod
    def from_vector(cls, loop: ControlLoop, v: np.ndarray) -> LoopState:
        """Inverse of :meth:`to_vector` for the blocks of `loop`."""
        n_r, n_c, n_m = loop.sizes()
        i = _kernel.N_FIXED
        return cls(v[0:2], v[2:5], v[5:7], v[7:10], v[i:i + n_r], v[i + n_r:i + n_r + n_c],
                   v[i + n_r + n_c:i + n_r + n_c + n_m])


def rest_state(loop: ControlLoop, r0: float = 0.0, y0: float = 0.0) -> LoopState:
    """Every block at rest: plant still at ``y0`` [m], sensors settled on their inputs.

    The PID's previous error is the error at rest, so the first derivative has no kick; the
    integral starts at zero (the double integrator needs no force at rest).

    Parameters
    ----------
    loop : ControlLoop
        The loop whose blocks are put at rest.
    r0 : float, default 0.0
        Reference at rest [m]: ``S_m``'s input and the PID's previous error.
    y0 : float, default 0.0
        Plant position at rest [m].

    Returns
    -------
    LoopState
        The state at rest.
    """
    x_r = loop.sensor.rest_state(y0)
    s0, _ = loop.sensor.step(x_r, y0, loop.ts)
    x_c = np.empty(0) if loop.compensator is None else loop.compensator.rest_state(s0)
    y_hat0 = y0 if loop.compensator is None else loop.compensator.step(x_c, s0, loop.ts)[0]
    x_m = np.empty(0) if loop.model is None else loop.model.rest_state(r0)
    if loop.scheme == "direct":
        e0 = r0 - y_hat0
    else:
        e0 = loop.sensor_gain * (loop.model.step(x_m, r0, loop.ts)[0] - s0)
    return LoopState([y0, 0.0], [0.0, e0, 0.0], [y0, 0.0], [y_hat0, 0.0, 0.0], x_r, x_c, x_m)


def tare(loop: ControlLoop, y0: float = 0.0) -> ControlLoop:
    """Zero the estimates on the sensor's reading at rest, as one zeroes a sensor at home.

    With the plant still at ``y0`` [m] the real sensor reads ``s0 = S_r(y0)`` at rest. Models
    fitted on recordings centred on their own means (eq. 5.10) disagree with it by the offset
    between recordings; in a loop no recording mean exists to remove. ``tare`` shifts the
    compensator's output offset so that it returns ``y0`` for ``s0`` at rest, and ``S_m``'s so
    that it returns ``s0`` for ``y0`` at rest. Only constant offsets change. (The document's
    future work asks for such a synchronisation of model and sensor, sec. 8.1.)

    Parameters
    ----------
    loop : ControlLoop
        The loop to zero.
    y0 : float, default 0.0
        Plant position at rest [m].

    Returns
    -------
    ControlLoop
        A copy with the compensator's and ``S_m``'s ``out_offset`` shifted.
    """
    s0, _ = loop.sensor.step(loop.sensor.rest_state(y0), y0, loop.ts)
    changes = {}
    if loop.compensator is not None:
        c = loop.compensator
        y_hat0, _ = c.step(c.rest_state(s0), s0, loop.ts)
        changes["compensator"] = replace(c, out_offset=c.out_offset + (y0 - y_hat0))
    if loop.model is not None:
        m = loop.model
        s_hat0, _ = m.step(m.rest_state(y0), y0, loop.ts)
        changes["model"] = replace(m, out_offset=m.out_offset + (s0 - s_hat0))
    return replace(loop, **changes)
