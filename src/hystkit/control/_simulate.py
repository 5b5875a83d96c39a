"""Running the closed loop: :func:`simulate_loop` calls the compiled kernel (``_kernel.py``),
:func:`simulate_loop_reference` is the same loop in plain Python over the blocks' readable
``step`` functions. Both take and return explicit state (:class:`~hystkit.control.LoopState`),
so a run split in two equals the whole run; a :class:`LoopResponse` holds one run's signals.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .._docfill import docfiller
from . import _kernel
from ._blocks import plant_matrices
from ._loop import ControlLoop, LoopState, rest_state

__all__ = ["LoopResponse", "simulate_loop", "simulate_loop_reference"]

# What both loop runs take and raise (the docstrings' %(input_noise)s, %(bad_run)s).
RUN_ENTRIES = {
    "input_noise": """d_in : array, optional
    Input force disturbance [N].
noise : array, optional
    Additive sensor noise [sensor units].""",
    "bad_run": """Raises
------
ValueError
    If `r` is empty, not 1-D or not finite, a disturbance is not shaped like `r`, or
    `state` does not match the loop's blocks.""",
}
fill_run_doc = docfiller(RUN_ENTRIES.__getitem__)


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
        import pandas as pd  # here: a loop run needs no pandas (0.15-0.19 s cpu to import)

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


@fill_run_doc
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
    %(input_noise)s

    Returns
    -------
    LoopResponse
        ``bounded`` is False if a value left the finite range or ``|y| > loop.y_limit``;
        the signals then stop before that step.

    %(bad_run)s
    """
    r, (d_out, d_in, noise), state = _prepare(loop, r, state, d_out, d_in, noise)
    args = (r, d_out, d_in, noise, state.to_vector(), *loop.kernel_arguments())
    compile_seconds = _kernel.compile_run(*args)  # JIT, first run of these blocks only
    t_start = time.perf_counter()
    out, x_end, n_done, reason = _kernel.run(*args)
    seconds = time.perf_counter() - t_start
    return _response(loop, r, t0, out, x_end, n_done, reason, seconds, compile_seconds)


@fill_run_doc
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
    %(input_noise)s

    Returns
    -------
    LoopResponse
        As :func:`simulate_loop`'s (``compile_seconds`` is 0).

    %(bad_run)s
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
