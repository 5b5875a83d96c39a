"""python-control adapters: hystkit models and loops as discrete-time ``nlsys`` objects.

For users who build and simulate systems in python-control: :func:`as_nlsys` wraps one
model, :func:`loop_nlsys` the whole loop of a :class:`ControlLoop` (same equations as the
compiled kernel, one Python call per block per step -- correct, and about a thousand times
slower; see ``benchmarks/bench_control.py``). State is python-control's, so these inherit its
explicit-state semantics (``initial_state`` in, ``states`` out).
"""

from __future__ import annotations

import control
import numpy as np

from ..compensation import Compensator
from ..models import family_of
from ._blocks import TS, plant_matrices
from ._loop import ControlLoop, LoopState, rest_state
from ._sensor_blocks import SensorBlock, compensator_block

__all__ = ["as_nlsys", "loop_initial_state", "loop_nlsys"]

Model = SensorBlock | Compensator | tuple


def _as_block(model: Model) -> SensorBlock:
    if isinstance(model, SensorBlock):
        return model
    if isinstance(model, Compensator):
        return compensator_block(model)
    if isinstance(model, tuple) and len(model) == 2:
        return SensorBlock(model[0], model[1], name=family_of(model[0]).name)
    raise TypeError(f"expected a SensorBlock, a Compensator or (structure, params) of a "
                    f"registered family, got {type(model).__name__}")


def as_nlsys(model: Model, dt: float = TS, *, name: str | None = None, input: str = "u",
             output: str = "y") -> control.NonlinearIOSystem:
    """A hystkit model of any family as a discrete-time python-control ``nlsys`` (step ``dt``).

    Parameters
    ----------
    model : SensorBlock, Compensator or (structure, params)
        A bare ``(structure, params)`` pair runs in normalised units; the others in their
        physical units (a compensator: sensor in, position [m] out).
    dt : float
        Sample time [s]; the model is re-stepped at it (``family.at``).
    name : str, optional
        System name and state prefix; default the block's name.
    input : str, default "u"
        Name of the input signal.
    output : str, default "y"
        Name of the output signal.

    Returns
    -------
    control.NonlinearIOSystem
        States ``<name>_x0 ..`` (the family's normalised state), one input and one output; the
        update and output functions are the family's readable ``step`` (or ``invert_step``),
        the same the plain-Python reference loop runs.
    """
    block = _as_block(model)
    name = block.name if name is None else name

    def update(t, x, u, params):
        return block.step(x, u[0], dt)[1]

    def out(t, x, u, params):
        return np.array([block.step(x, u[0], dt)[0]])

    return control.nlsys(update, out, inputs=[input], outputs=[output],
                         states=[f"{name}_x{k}" for k in range(block.n_state)], dt=dt,
                         name=name)


def _plant(loop: ControlLoop) -> control.NonlinearIOSystem:
    ts = loop.ts
    _, b, _ = plant_matrices(loop.plant.mass, ts)

    def update(t, x, u, params):
        force = u[0] + u[1]
        return np.array([x[0] + ts * x[1] + b[0] * force, x[1] + b[1] * force])

    def out(t, x, u, params):
        return np.array([x[0] + u[2]])

    return control.nlsys(update, out, inputs=["u", "d_in", "d_out"], outputs=["y"],
                         states=["position", "velocity"], dt=ts, name="plant")


def _controller(loop: ControlLoop) -> control.NonlinearIOSystem:
    """PID (eq. 7.2) + force limit + plant estimate (fig. 7.11) + DOB, as in the kernel."""
    ts, p = loop.ts, loop.pid
    _, b_n, _ = plant_matrices(loop.mass_n, ts)
    ki = ts / p.ti if np.isfinite(p.ti) else 0.0
    gain = None if loop.dob is None else loop.dob.observer_gain(loop.mass_n, ts)

    def force(x, e):
        d = (p.tf * x[2] + p.td * (e - x[1])) / (p.tf + ts)
        wanted = p.kp * (e + x[0] + d) - (x[7] if gain is not None else 0.0)
        return d, wanted, float(np.clip(wanted, -loop.plant.u_max, loop.plant.u_max))

    def update(t, x, u, params):
        e, y_hat = u[0], u[1]
        d, wanted, f = force(x, e)
        frozen = p.anti_windup and f != wanted and p.kp * e * wanted > 0
        nxt = np.array([x[0] + (0.0 if frozen else ki * e), e, d,
                        x[3] + ts * x[4] + b_n[0] * f, x[4] + b_n[1] * f, x[5], x[6], x[7]])
        if gain is not None:
            innov = y_hat - x[5]
            nxt[5:] = [x[5] + ts * x[6] + b_n[0] * (f + x[7]) + gain[0] * innov,
                       x[6] + b_n[1] * (f + x[7]) + gain[1] * innov, x[7] + gain[2] * innov]
        return nxt

    def out(t, x, u, params):
        return np.array([force(x, u[0])[2], x[3]])

    return control.nlsys(update, out, inputs=["e", "y_hat"], outputs=["u", "y_hat_plant"],
                         states=["integral", "e_prev", "derivative", "est_position",
                                 "est_velocity", "dob_position", "dob_velocity", "dob_force"],
                         dt=ts, name="controller")


def loop_nlsys(loop: ControlLoop) -> control.InterconnectedSystem:
    """The whole loop as one python-control system.

    Inputs ``r`` [m], ``d_in`` [N], ``d_out`` [m]; outputs ``y, s, y_hat, e, u, y_hat_plant``
    and, with ``S_m``, ``s_hat`` (``y_hat`` is 0 without a compensator). State order: plant,
    S_r, compensator, S_m, controller; :func:`loop_initial_state` builds it from a
    :class:`LoopState`.

    Parameters
    ----------
    loop : ControlLoop
        The loop to convert.

    Returns
    -------
    control.InterconnectedSystem
        Discrete-time system with sample time ``loop.ts``.
    """
    ts = loop.ts
    systems = [_plant(loop), as_nlsys(loop.sensor, ts, name="S_r", input="y", output="s")]
    if loop.compensator is not None:
        systems.append(as_nlsys(loop.compensator, ts, name="comp", input="s", output="y_hat"))
    else:
        systems.append(control.nlsys(None, lambda t, x, u, p: np.array([0.0]), inputs=["s"],
                                     outputs=["y_hat"], dt=ts, name="comp"))
    if loop.model is not None:
        systems.append(as_nlsys(loop.model, ts, name="S_m", input="r", output="s_hat"))
    if loop.scheme == "direct":
        systems.append(control.summing_junction(["r", "-y_hat"], "e", name="error"))
    else:
        g = loop.sensor_gain
        systems.append(control.nlsys(None, lambda t, x, u, p: np.array([g * (u[0] - u[1])]),
                                     inputs=["s_hat", "s"], outputs=["e"], dt=ts,
                                     name="error"))
    systems.append(_controller(loop))
    outputs = ["y", "s", "y_hat", "e", "u", "y_hat_plant"]
    return control.interconnect(systems, inplist=["r", "d_in", "d_out"],
                                outlist=outputs + (["s_hat"] if loop.model is not None else []),
                                name="loop", dt=ts)


def loop_initial_state(loop: ControlLoop, state: LoopState | None = None,
                       r0: float = 0.0) -> np.ndarray:
    """:class:`LoopState` (default: at rest at ``r0``) in :func:`loop_nlsys` state order.

    Parameters
    ----------
    loop : ControlLoop
        The loop the state belongs to.
    state : LoopState, optional
        State to convert; default :func:`rest_state` at `r0`.
    r0 : float, default 0.0
        Reference at rest [m] when `state` is None.

    Returns
    -------
    numpy.ndarray
        Plant, S_r, compensator, S_m, PID, plant-estimate and DOB states, concatenated.
    """
    state = rest_state(loop, r0) if state is None else state
    return np.concatenate([state.plant, state.sensor, state.compensator, state.model,
                           state.pid, state.estimate, state.dob])
