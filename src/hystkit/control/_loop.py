"""Closed position loop with a hysteretic sensor (ch. 7): configuration, state, simulation.

Schemes (both with the optional disturbance observer of sec. 7.4):

- ``direct`` (a), fig. 7.1: ``e = r - y_hat`` with ``y_hat = compensator(s)``, ``s = S_r(y)``;
- ``weighting`` (b), fig. 7.8: ``e = g_s (S_m(r) - s)``; ``g_s`` [m per sensor unit] is a fixed
  straight-line calibration so the PID sees metres in both schemes. The plant estimate of
  fig. 7.11 (nominal plant driven by the applied force) is recorded in every run.

:func:`simulate_loop` runs the compiled kernel; :func:`simulate_loop_reference` is the same loop
in plain Python over the blocks' readable ``step`` functions. Both take and return explicit
state, so a run split in two equals the whole run.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from . import _kernel
from ._blocks import PID, TS, DisturbanceObserver, Plant, plant_matrices
from ._names import SCHEMES
from ._sensor_blocks import SensorBlock

__all__ = ["SCHEMES", "ControlLoop", "LoopResponse", "LoopState", "rest_state",
           "simulate_loop", "simulate_loop_reference", "tare"]



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


@dataclass(frozen=True, eq=False)
class LoopResponse:
    """Signals of one run, the state after it and whether it stayed bounded.

    Signal arrays hold only the steps that ran: an unbounded run is cut at the first bad step
    (``stop_step``, ``stop_time``, ``stop_reason``), never padded with NaN, and ``state`` is
    None (a diverged run cannot be continued). ``y_hat`` is None
    without a compensator, ``s_hat`` without ``S_m``, ``d_hat`` without a DOB.

    Parameters
    ----------
    scheme : {"direct", "weighting"}
        Scheme of the loop that ran.
    t : numpy.ndarray, shape (n,)
        Time [s].
    r, y : numpy.ndarray, shape (n,)
        Reference and plant position [m] (``y`` includes the output disturbance).
    s : numpy.ndarray, shape (n,)
        Sensor signal [sensor units].
    y_hat : numpy.ndarray or None
        Compensator's position estimate [m].
    s_hat : numpy.ndarray or None
        ``S_m``'s output [sensor units].
    y_hat_plant : numpy.ndarray, shape (n,)
        Nominal-plant position estimate [m] (fig. 7.11).
    e : numpy.ndarray, shape (n,)
        Tracking error the PID sees [m].
    u : numpy.ndarray, shape (n,)
        Applied force [N].
    d_hat : numpy.ndarray or None
        DOB force estimate [N].
    state : LoopState or None
        State after the last step; None when the run was cut.
    bounded : bool
        Every requested step ran.
    n_requested : int
        Steps asked for (``r.size`` of the call).
    stop_step, stop_time, stop_reason : int, float, str or None
        First step not run, its time [s] and why; None when bounded.
    seconds : float
        Wall time of the simulation [s], JIT compilation excluded.
    compile_seconds : float
        JIT compilation of the loop kernel before the run [s] (0 when this combination of
        blocks was compiled before in the process).
    """

    scheme: str
    t: np.ndarray
    r: np.ndarray
    y: np.ndarray
    s: np.ndarray
    y_hat: np.ndarray | None
    s_hat: np.ndarray | None
    y_hat_plant: np.ndarray
    e: np.ndarray
    u: np.ndarray
    d_hat: np.ndarray | None
    state: LoopState | None
    bounded: bool
    n_requested: int
    stop_step: int | None = None
    stop_time: float | None = None
    stop_reason: str | None = None
    seconds: float = 0.0
    compile_seconds: float = 0.0

    @property
    def plant_error(self) -> np.ndarray:
        """``e_p = r - y`` [m], the error that matters (eq. 7.6, 7.8)."""
        return self.r - self.y

    def metrics(self) -> dict:
        """Plant and tracking errors (eq. 7.6, 7.8), boundedness and wall time; JSON-safe.

        ``e_p_max`` is ``max |r - y|``; ``e_p_max_signed`` is the signed value there (the
        document does not say which it reports). ``e_p_max_settled`` leaves out the first 2 s
        (one period of the trained 0.5 Hz sine: the start-up transient), when the run is longer.
        """
        e_p = self.plant_error
        out = {"bounded": self.bounded, "seconds": self.seconds,
               "compile_seconds": self.compile_seconds, "n_steps": int(self.t.size),
               "n_requested": self.n_requested}
        if e_p.size:
            i = int(np.argmax(np.abs(e_p)))
            out.update(e_p_max=float(abs(e_p[i])), e_p_max_signed=float(e_p[i]),
                       e_p_mean=float(np.mean(e_p)), e_p_rms=float(np.sqrt(np.mean(e_p ** 2))),
                       tracking_rms=float(np.sqrt(np.mean(self.e ** 2))),
                       tracking_mean=float(np.mean(self.e)))
            settled = self.t >= self.t[0] + 2.0
            if np.any(settled):
                out["e_p_max_settled"] = float(np.max(np.abs(e_p[settled])))
            if self.y_hat is not None:
                out["estimate_rms"] = float(np.sqrt(np.mean((self.y_hat - self.y) ** 2)))
        if not self.bounded:
            out.update(stop_step=self.stop_step, stop_time=self.stop_time,
                       stop_reason=self.stop_reason)
        return out

    def to_pandas(self):
        """The signals as a DataFrame indexed by time (absent signals left out)."""
        cols = {name: getattr(self, name) for name in
                ("r", "y", "s", "y_hat", "s_hat", "y_hat_plant", "e", "u", "d_hat")
                if getattr(self, name) is not None}
        return pd.DataFrame(cols, index=pd.Index(self.t, name="t"))


def _prepare(loop: ControlLoop, r, state, d_out, d_in, noise):
    r = np.ascontiguousarray(r, dtype=float)
    if r.ndim != 1 or r.size == 0 or not np.all(np.isfinite(r)):
        raise ValueError("r must be a non-empty, finite 1-D array [m]")
    extra = []
    for name, a in (("d_out", d_out), ("d_in", d_in), ("noise", noise)):
        a = np.zeros_like(r) if a is None else np.ascontiguousarray(a, dtype=float)
        if a.shape != r.shape or not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be finite and shaped like r")
        extra.append(a)
    state = rest_state(loop, float(r[0])) if state is None else state
    n_r, n_c, n_m = loop.sizes()
    if (state.sensor.size, state.compensator.size, state.model.size) != (n_r, n_c, n_m):
        raise ValueError("state does not match the loop's blocks")
    return r, extra, state


def _response(loop, r, t0, out, x_end, n_done, reason, seconds,
              compile_seconds=0.0) -> LoopResponse:
    sig = dict(zip(_kernel.SIGNALS, out[:, :n_done], strict=True))
    bounded = reason == 0
    return LoopResponse(
        scheme=loop.scheme, t=t0 + np.arange(n_done) * loop.ts, r=r[:n_done], y=sig["y"],
        s=sig["s"], y_hat=sig["y_hat"] if loop.compensator is not None else None,
        s_hat=sig["s_hat"] if loop.model is not None else None,
        y_hat_plant=sig["y_hat_plant"], e=sig["e"], u=sig["u"],
        d_hat=sig["d_hat"] if loop.dob is not None else None,
        state=LoopState.from_vector(loop, x_end) if bounded else None, bounded=bounded,
        n_requested=r.size,
        stop_step=None if bounded else int(n_done),
        stop_time=None if bounded else float(t0 + n_done * loop.ts),
        stop_reason=None if bounded else _kernel.STOP_REASONS[reason], seconds=seconds,
        compile_seconds=compile_seconds)


def simulate_loop(loop: ControlLoop, r: np.ndarray, *, state: LoopState | None = None,
                  t0: float = 0.0, d_out: np.ndarray | None = None,
                  d_in: np.ndarray | None = None,
                  noise: np.ndarray | None = None) -> LoopResponse:
    """Run the closed loop over the reference ``r`` (compiled, one kernel call).

    Parameters
    ----------
    loop : ControlLoop
    r : array, shape (n,)
        Reference position [m], one value per sample ``Ts``.
    state : LoopState, optional
        Start here (e.g. ``previous.state``); default :func:`rest_state` at ``r[0]``.
    t0 : float
        Time of the first sample [s] (only labels ``t``).
    d_out : array, optional
        Output disturbance [m] added to the plant position (sec. 7.3.2); the sensor sees it and
        it counts in the plant error.
    d_in : array, optional
        Input force disturbance [N].
    noise : array, optional
        Additive sensor noise [sensor units].

    Returns
    -------
    LoopResponse
        ``bounded`` is False if a value left the finite range or ``|y| > loop.y_limit``;
        the signals then stop before that step.

    Raises
    ------
    ValueError
        If `r` is empty, not 1-D or not finite, a disturbance is not shaped like `r`, or
        `state` does not match the loop's blocks.
    """
    r, (d_out, d_in, noise), state = _prepare(loop, r, state, d_out, d_in, noise)
    args = (r, d_out, d_in, noise, state.to_vector(), *loop.kernel_arguments())
    compile_seconds = _kernel.compile_run(*args)  # JIT, first run of these blocks only
    t_start = time.perf_counter()
    out, x_end, n_done, reason = _kernel.run(*args)
    seconds = time.perf_counter() - t_start
    return _response(loop, r, t0, out, x_end, n_done, reason, seconds, compile_seconds)


def simulate_loop_reference(loop: ControlLoop, r: np.ndarray, *,
                            state: LoopState | None = None, t0: float = 0.0,
                            d_out: np.ndarray | None = None, d_in: np.ndarray | None = None,
                            noise: np.ndarray | None = None) -> LoopResponse:
    """Same as :func:`simulate_loop` as a plain Python loop over readable block steps.

    Parameters
    ----------
    loop : ControlLoop
        The loop to run.
    r : array, shape (n,)
        Reference position [m], one value per sample ``Ts``.
    state : LoopState, optional
        Start here; default :func:`rest_state` at ``r[0]``.
    t0 : float
        Time of the first sample [s] (only labels ``t``).
    d_out : array, optional
        Output disturbance [m] added to the plant position.
    d_in : array, optional
        Input force disturbance [N].
    noise : array, optional
        Additive sensor noise [sensor units].

    Returns
    -------
    LoopResponse
        As :func:`simulate_loop`'s (``compile_seconds`` is 0).

    Raises
    ------
    ValueError
        If `r` is empty, not 1-D or not finite, a disturbance is not shaped like `r`, or
        `state` does not match the loop's blocks.
    """
    r, (d_out, d_in, noise), state = _prepare(loop, r, state, d_out, d_in, noise)
    ts, p = loop.ts, loop.pid
    _, b, _ = plant_matrices(loop.plant.mass, ts)
    _, b_n, _ = plant_matrices(loop.mass_n, ts)
    gain_l = None if loop.dob is None else loop.dob.observer_gain(loop.mass_n, ts)
    pos, vel = state.plant
    integral, e_prev, d_prev = state.pid
    est = state.estimate.copy()
    obs = state.dob.copy()
    x_r, x_c, x_m = state.sensor.copy(), state.compensator.copy(), state.model.copy()
    out = np.zeros((8, r.size))
    reason, n_done = 0, r.size
    t_start = time.perf_counter()
    for n in range(r.size):
        y = pos + d_out[n]
        s, x_r_next = loop.sensor.step(x_r, y, ts)
        s += noise[n]
        y_hat, x_c_next = (0.0, x_c) if loop.compensator is None else \
            loop.compensator.step(x_c, s, ts)
        s_hat, x_m_next = (0.0, x_m) if loop.model is None else loop.model.step(x_m, r[n], ts)
        e = r[n] - y_hat if loop.scheme == "direct" else loop.sensor_gain * (s_hat - s)
        d = (p.tf * d_prev + p.td * (e - e_prev)) / (p.tf + ts)  # eq. 7.2 when Tf = 0
        u_wanted = p.kp * (e + integral + d) - (obs[2] if gain_l is not None else 0.0)
        u = float(np.clip(u_wanted, -loop.plant.u_max, loop.plant.u_max))
        frozen = p.anti_windup and u != u_wanted and p.kp * e * u_wanted > 0
        if np.isfinite(p.ti) and not frozen:
            integral_next = integral + ts / p.ti * e
        else:
            integral_next = integral
        est_next = np.array([est[0] + ts * est[1] + b_n[0] * u, est[1] + b_n[1] * u])
        obs_next = obs
        if gain_l is not None:
            innov = y_hat - obs[0]
            obs_next = np.array([
                obs[0] + ts * obs[1] + b_n[0] * (u + obs[2]) + gain_l[0] * innov,
                obs[1] + b_n[1] * (u + obs[2]) + gain_l[1] * innov,
                obs[2] + gain_l[2] * innov])
        force = u + d_in[n]
        if not abs(y) <= loop.y_limit:
            reason = 1
        elif not np.isfinite(u):
            reason = 2
        elif not np.all(np.isfinite([s, y_hat, s_hat, e])):
            reason = 3
        if reason:
            n_done = n
            break
        out[:, n] = (y, s, y_hat, s_hat, est[0], e, u, obs[2] if gain_l is not None else 0.0)
        pos, vel = pos + ts * vel + b[0] * force, vel + b[1] * force
        integral, e_prev, d_prev = integral_next, e, d
        est, obs, x_r, x_c, x_m = est_next, obs_next, x_r_next, x_c_next, x_m_next
    x_end = np.concatenate([[pos, vel, integral, e_prev, d_prev], est, obs, x_r, x_c, x_m])
    return _response(loop, r, t0, out, x_end, n_done, reason, time.perf_counter() - t_start)
