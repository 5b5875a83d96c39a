"""Sensor blocks for the loop: fitted hysteresis models of any family in physical units.

A :class:`SensorBlock` wraps a fitted model of any registered family (``hystkit.models``) with
the affine maps between the loop's physical units and the normalised units the model was fitted
in (eq. 5.10)::

    u_norm = (input - in_offset) / in_scale        # metres or sensor units in
    output = out_scale * model(u_norm) + out_offset

- the "real" sensor ``S_r`` maps plant position [m] to the sensor signal; it is a *forward*
  model fitted position -> sensor (:func:`fit_forward_sensor`), or a model file run in the
  position -> sensor direction (:func:`sensor_block`);
- the compensator maps the sensor signal to a position estimate [m]
  (:func:`compensator_block`, from a :class:`~hystkit.compensation.Compensator`, direct or
  inverse mode);
- the model ``S_m`` of scheme (b) is another forward model, fitted separately.

Everything family-specific goes through the family protocol (``step``, ``invert_step``,
``rest_state``, ``at``, ``linearise``, ``block``), so any family runs in any slot.

Sample time. A model fitted at the recordings' 40 Hz runs at the loop's ``Ts`` as
``family.at(structure, Ts)`` decides: for the mPL the same ODE integrated with the finer step,
its Euler slope cap rising with it (``docs/control.md`` quantifies what this changes); a family
that cannot change its sample time refuses with the reason.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..compensation import Compensator, Scaling, fit_compensator
from ..errors import InputError
from ..io import Recording
from ..models import Family, family_of, get_family
from ..sensors import VIRTUAL_PHYSICS, VirtualSensor, physics_of, simulate_experiment
from . import _kernel
from ._names import TRAININGS

__all__ = [
    "TRAININGS",
    "SensorBlock",
    "SensorModels",
    "compensator_block",
    "fit_forward_sensor",
    "fit_sensor_models",
    "forward_block",
    "linear_block",
    "sensor_block",
    "table_ii_sensor",
    "table_ii_sensors",
    "virtual_sensor_block",
]

MM = 1e-3  # recordings hold position in mm; the loop works in metres


@dataclass(frozen=True, eq=False)
class SensorBlock:
    """A fitted model between physical signals; pure, state passed in and out.

    Parameters
    ----------
    structure, params
        A registered family's structure and parameters as fitted (``structure.dt`` is the
        fitting sample time; the loop re-steps it at ``Ts``). ``None`` and ``None`` make the
        ideal memoryless block ``out = out_scale * u_norm + out_offset`` (:func:`linear_block`).
    inverse : bool
        Run the family's inverse instead of the model itself (a compensator fitted in inverse
        mode, or a sensor -> position model used as a position -> sensor sensor).
    in_offset, in_scale : float
        Input normalisation, input units (m for a sensor, sensor units for a compensator).
    out_offset, out_scale : float
        Output de-normalisation, output units.
    name : str
    info : dict
        Provenance: training source, fit cost and R^2 (free-form, JSON-safe).
    model_family : Family, optional
        The family to run ``structure`` with; default the registered family whose
        ``Structure`` it is. A model that is not a fittable family (e.g. the virtual sensor's
        physics, :mod:`hystkit.sensors`) passes an object with the protocol's running methods
        (``rest_state``, ``step``, ``simulate``, ``at``, ``block``, ``linearise``).
    """

    structure: Any
    params: Any
    inverse: bool = False
    in_offset: float = 0.0
    in_scale: float = 1.0
    out_offset: float = 0.0
    out_scale: float = 1.0
    name: str = "model"
    info: dict = field(default_factory=dict)
    model_family: Any = None

    def __post_init__(self) -> None:
        for key in ("in_offset", "in_scale", "out_offset", "out_scale"):
            if not np.isfinite(getattr(self, key)):
                raise ValueError(f"{key} must be finite")
        if self.in_scale == 0 or self.out_scale == 0:
            raise ValueError("in_scale and out_scale must be non-zero")
        if (self.structure is None) != (self.params is None):
            raise ValueError("give both structure and params, or neither (an ideal block)")
        if self.structure is None:
            if self.inverse:
                raise ValueError("the ideal linear block has no inverse mode")
            return
        family = self.family
        if not isinstance(self.params, family.Params):
            raise TypeError(f"params of type {type(self.params).__name__} do not belong to "
                             f"the {family.name} family")
        if self.inverse and not family.has_inverse:
            raise ValueError(f"{self.name}: model {family.name!r} has no inverse "
                             f"({family.no_inverse_reason})")
        # A short run makes the family check that structure and params belong together.
        run = family.invert if self.inverse else family.simulate
        run(self.structure, self.params, np.zeros(2))

    @property
    def family(self) -> Family | None:
        """The model's family; None for the ideal linear block."""
        if self.structure is None:
            return None
        return self.model_family if self.model_family is not None else family_of(self.structure)

    @property
    def n_state(self) -> int:
        """Length of the block's state vector."""
        if self.structure is None:
            return 0
        return int(np.size(self.family.rest_state(self.structure, self.params, 0.0,
                                                  self.inverse)))

    def at(self, dt: float):
        """The model's structure re-stepped at ``dt`` (``family.at``)."""
        return None if self.structure is None else self.family.at(self.structure, dt)

    def _norm(self, u_in: float) -> float:
        return (u_in - self.in_offset) / self.in_scale

    def rest_state(self, u_in: float) -> np.ndarray:
        """State at rest for a constant physical input ``u_in``."""
        if self.structure is None:
            return np.empty(0)
        return np.asarray(self.family.rest_state(self.structure, self.params,
                                                 float(self._norm(u_in)), self.inverse),
                          dtype=float)

    def step(self, x: np.ndarray, u_in: float, dt: float) -> tuple[float, np.ndarray]:
        """One sample (readable reference): output from the present state, then the update."""
        u = self._norm(u_in)
        if self.structure is None:
            return self.out_scale * u + self.out_offset, np.empty(0)
        run = self.family.invert_step if self.inverse else self.family.step
        y, x_next = run(self.at(dt), self.params, np.asarray(x, dtype=float), u)
        return self.out_scale * y + self.out_offset, np.asarray(x_next, dtype=float)

    def simulate(self, u_in: np.ndarray, dt: float,
                 x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Run the block open loop over ``u_in`` (physical units) at sample time ``dt``.

        Returns
        -------
        out : array, shape (n,)
        x_end : array, shape (n_state,)
        """
        u_in = np.asarray(u_in, dtype=float)
        u = (u_in - self.in_offset) / self.in_scale
        if self.structure is None:
            return self.out_scale * u + self.out_offset, np.empty(0)
        x0 = self.rest_state(float(u_in[0])) if x0 is None else x0
        run = self.family.invert if self.inverse else self.family.simulate
        y, x_end = run(self.at(dt), self.params, u, x0)
        return self.out_scale * y + self.out_offset, x_end

    def pack(self, dt: float) -> tuple[Any, np.ndarray, np.ndarray]:
        """``(step, affine, body)`` for the compiled loop at sample time ``dt``: the family's
        block step, ``[a_in, b_in, a_out, b_out]`` (``u_norm = a_in u + b_in``, ``out =
        a_out y + b_out``) and the family's packed parameters."""
        affine = np.array([1.0 / self.in_scale, -self.in_offset / self.in_scale,
                           self.out_scale, self.out_offset])
        if self.structure is None:
            return _kernel.identity_step, affine, np.empty(0)
        block = self.family.block(self.at(dt), self.params, self.inverse)
        return block.step, affine, np.ascontiguousarray(block.body, dtype=np.float64)

    def linearise(self, x: np.ndarray, u_in: float,
                  dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Discrete linearisation ``(A, B, C, D)`` at state ``x`` and input ``u_in``, physical
        units (``family.linearise``: analytical where the family has it)."""
        if self.structure is None:
            empty = np.empty((0, 0))
            return empty, np.empty(0), np.empty(0), self.out_scale / self.in_scale
        a, b, c, d = self.family.linearise(self.at(dt), self.params,
                                           np.asarray(x, dtype=float), self._norm(u_in),
                                           self.inverse)
        return (np.asarray(a, dtype=float), np.asarray(b, dtype=float) / self.in_scale,
                self.out_scale * np.asarray(c, dtype=float),
                float(self.out_scale * d / self.in_scale))


def _normalise(recording: Recording) -> tuple[Scaling, np.ndarray, np.ndarray]:
    """Centre on the recording's means and scale by max |.| (eq. 5.10); position in mm."""
    s_off, p_off = float(np.mean(recording.sensor)), float(np.mean(recording.position))
    s, p = recording.sensor - s_off, recording.position - p_off
    scaling = Scaling(s_off, float(np.max(np.abs(s))), p_off, float(np.max(np.abs(p))))
    if scaling.sensor_scale == 0 or scaling.position_scale == 0:
        raise InputError(f"{recording.source}: constant signal; nothing to fit")
    return scaling, s / scaling.sensor_scale, p / scaling.position_scale


def _r2(y: np.ndarray, target: np.ndarray) -> float:
    return float(1 - np.sum((y - target) ** 2) / np.sum((target - target.mean()) ** 2))


def forward_block(structure: Any, params: Any, scaling: Scaling, *, name: str = "sensor",
                  info: dict | None = None) -> SensorBlock:
    """Forward model position [m] -> sensor from a fit on normalised mm data.

    Parameters
    ----------
    structure, params
        A registered family's structure and parameters, fitted position -> sensor on
        normalised data.
    scaling : Scaling
        The normalisation of the fit (position offset and scale in mm).
    name : str, default "sensor"
        Block name.
    info : dict, optional
        Provenance, copied into the block.

    Returns
    -------
    SensorBlock
        Position [m] in, sensor signal out.
    """
    return SensorBlock(structure, params, False, scaling.position_offset * MM,
                       scaling.position_scale * MM, scaling.sensor_offset, scaling.sensor_scale,
                       name=name, info=dict(info or {}))


def fit_forward_sensor(recording: Recording, size: int | None = 3, *, model: str = "mpl",
                       name: str = "sensor", **structure_options: Any) -> SensorBlock:
    """Fit a forward model (position -> sensor, the sensor's own direction) on a recording.

    ``family.fit(position_norm, sensor_norm)`` on the recording centred on its means and scaled
    by its max |.| (eq. 5.10); ``size`` is the family's size knob (None: its default).
    ``info`` records the source, the SSE, the R^2 on the fitting data and the straight-line
    gain ``position per sensor unit`` [m / sensor unit], which scheme (b) uses to express the
    sensor error in metres.

    Parameters
    ----------
    recording : Recording
        Sensor recording with a ``position`` column [mm].
    size : int or None, default 3
        The family's size knob; None for its default.
    model : str, default "mpl"
        Registered family to fit.
    name : str, default "sensor"
        Block name.
    **structure_options
        Passed to the family's ``make_structure`` (mPL: ``slope_cap``).

    Returns
    -------
    SensorBlock
        The fitted forward block, position [m] in, sensor signal out.

    Raises
    ------
    InputError
        If the recording has no position column or a constant signal, or `model` is unknown.
    """
    if not recording.has_position():
        raise InputError(f"{recording.source}: column 'position' is needed to fit a sensor")
    family = get_family(model)
    size = family.default_size if size is None else size
    scaling, s, p = _normalise(recording)
    structure = family.make_structure(recording.dt, size, **structure_options)
    result = family.fit(p, s, structure)
    y, _ = family.simulate(structure, result.params, p)
    gain = np.polyfit(recording.sensor, recording.position * MM, 1)[0]
    info = {"source": recording.source, "direction": "position -> sensor", "model": model,
            "size": size, "fit_dt": recording.dt, "sse": result.cost, "r2": _r2(y, s),
            "fit_seconds": result.seconds, "m_per_sensor_unit": float(gain)}
    return forward_block(structure, result.params, scaling, name=name, info=info)


def _offsets(compensator: Compensator) -> tuple[float, float]:
    """A loop has no recording to take offsets from: the fitting recording's, for every
    centring except ``none`` (the ``fit`` centring of :mod:`hystkit.compensation`);
    :func:`~hystkit.control.tare` then zeroes the estimates at rest."""
    sc = compensator.scaling
    return (0.0, 0.0) if compensator.center == "none" else (sc.sensor_offset,
                                                            sc.position_offset)


def _sensor_scale(compensator: Compensator) -> float:
    """Sensor units per normalised unit, signed: the model sees the sensor flipped by the
    file's ``polarity`` (a sensor that falls with position)."""
    return compensator.scaling.sensor_scale * compensator.polarity


def _file_info(compensator: Compensator, direction: str) -> dict:
    info = {k: v for k, v in compensator.fit_info.items()
            if isinstance(v, str | int | float | bool)}
    info.update(model=compensator.model, mode=compensator.mode, direction=direction)
    return info


def compensator_block(compensator: Compensator, *, name: str = "compensator") -> SensorBlock:
    """The compensator as a loop block: sensor signal in, position estimate [m] out.

    Direct mode runs the fitted model; inverse mode runs the inverse of the forward model it
    holds. Offsets: see :func:`_offsets`.

    Parameters
    ----------
    compensator : Compensator
        A fitted compensator (a model file).
    name : str, default "compensator"
        Block name.

    Returns
    -------
    SensorBlock
        Sensor signal in, position estimate [m] out.
    """
    s_off, p_off = _offsets(compensator)
    return SensorBlock(compensator.structure, compensator.params,
                       compensator.mode == "inverse", s_off, _sensor_scale(compensator),
                       p_off * MM, compensator.scaling.position_scale * MM, name=name,
                       info=_file_info(compensator, "sensor -> position"))


def sensor_block(compensator: Compensator, *, name: str = "S_r") -> SensorBlock:
    """A model file run in the sensor's own direction: position [m] in, sensor signal out.

    An inverse-mode file holds a forward model (position -> sensor): it runs as is. A
    direct-mode file holds sensor -> position: it runs backwards through its family's inverse,
    and a family without one is refused with the reason (``ValueError``).

    Parameters
    ----------
    compensator : Compensator
        A fitted compensator (a model file).
    name : str, default "S_r"
        Block name.

    Returns
    -------
    SensorBlock
        Position [m] in, sensor signal out.

    Raises
    ------
    ValueError
        If the file is in direct mode and its family has no inverse.
    """
    s_off, p_off = _offsets(compensator)
    return SensorBlock(compensator.structure, compensator.params,
                       compensator.mode == "direct", p_off * MM,
                       compensator.scaling.position_scale * MM, s_off,
                       _sensor_scale(compensator), name=name,
                       info=_file_info(compensator, "position -> sensor"))


def linear_block(gain: float, offset: float = 0.0, *, name: str = "linear") -> SensorBlock:
    """An ideal, memoryless linear block ``out = gain * input + offset`` (no state).

    The property tests' ideal sensor and exact compensator; it runs through the same compiled
    loop as the fitted models.

    Parameters
    ----------
    gain : float
        Slope, output units per input unit; finite and non-zero.
    offset : float, default 0.0
        Output at zero input.
    name : str, default "linear"
        Block name.

    Returns
    -------
    SensorBlock
        The memoryless block.

    Raises
    ------
    ValueError
        If `gain` is zero or not finite.
    """
    if not (np.isfinite(gain) and gain != 0):
        raise ValueError(f"gain must be finite and non-zero, got {gain!r}")
    return SensorBlock(None, None, False, 0.0, 1.0, float(offset), float(gain), name=name,
                       info={"kind": "ideal linear", "gain": gain})




@dataclass(frozen=True, eq=False)
class SensorModels:
    """The three models of ch. 7, fitted separately (never one object twice, sec. 6.2.2).

    Parameters
    ----------
    sensor : SensorBlock
        ``S_r``, the "real" sensor: position [m] -> sensor.
    compensator : SensorBlock
        ``S_m^comp``: sensor -> position estimate [m] (scheme (a); estimate and DOB of (b)).
    model : SensorBlock
        ``S_m``: forward model position [m] -> sensor, weights the reference in scheme (b).
    sensor_gain : float
        Straight-line gain [m per sensor unit] of ``S_m``'s training data; scheme (b) multiplies
        its sensor-unit error by it so that the PID sees metres, as in scheme (a).
    info : dict
        Provenance: training kind and sources, families and sizes.
    """

    sensor: SensorBlock
    compensator: SensorBlock
    model: SensorBlock
    sensor_gain: float
    info: dict = field(default_factory=dict)


def fit_sensor_models(*, training: str = "recording", sensor_cells: int | None = None,
                      model_cells: int | None = None, sensor_seed: int = 1,
                      training_seed: int = 2, training_excitation: str = "sine",
                      sensor_recording: Recording | None = None,
                      training_recording: Recording | None = None,
                      sensor: SensorBlock | None = None, sensor_model: str = "mpl",
                      model: str = "mpl") -> SensorModels:
    """Fit ``S_r``, the compensator and ``S_m`` as the document's ch. 7 does (about 2 s).

    ``S_r`` is a forward model of family ``sensor_model`` fitted on the sensor recording
    (default: the virtual sensor's noise experiment, seed ``sensor_seed``: the document's choice
    of the noise-trained model as the real sensor, fig. 7.2). The compensator (direct mode,
    sensor -> position) and ``S_m`` (forward), of family ``model``, come from separate training
    data:

    ``training="recording"`` (default)
        The virtual sensor's ``training_excitation`` experiment (default the 0.5 Hz, 3 mm sine),
        another seed: the compensator is trained on the lab sensor at one excitation, as the
        document's is, and ``S_r`` differs from the sensor it was trained on by ``S_r``'s own
        model error -- the realistic case.
    ``training="loop"``
        The document's protocol (sec. 7.2, 7.5): ``S_r`` itself is run on the 0.5 Hz, 3 mm
        sine (ideal position tracking, 200 s at the fitting rate) and the compensator and
        ``S_m`` are fitted to its response. Noise-free model data let a model of ``S_r``'s
        structure reproduce it exactly -- the unrealistic identity of sec. 6.2.2 -- so
        ``model_cells`` defaults to 1 here (the document's N = 1, paper 9.2) and an exact
        reproduction is refused.

    Parameters
    ----------
    training : {"recording", "loop"}, default "recording"
        Training data of the compensator and ``S_m``, as above.
    sensor_cells, model_cells : int, optional
        Size knob of ``S_r`` and of the compensator / ``S_m``. Defaults: for the mPL 3 cells
        (1 for the compensator and ``S_m`` with ``training="loop"``), for other families their
        default size.
    sensor_seed : int, default 1
        Seed of the virtual sensor's noise experiment ``S_r`` is fitted on.
    training_seed : int, default 2
        Seed of the virtual sensor's training recording (``training="recording"``).
    training_excitation : str, default "sine"
        Excitation of that training recording (:func:`~hystkit.sensors.simulate_experiment`).
    sensor_recording, training_recording : Recording, optional
        Use these instead of the virtual sensor's.
    sensor : SensorBlock, optional
        A ready ``S_r`` (e.g. :func:`table_ii_sensor` or :func:`sensor_block`) instead of a
        fit; its ``fit_dt`` is the rate of the ``loop`` training run.
    sensor_model, model : str
        Registered families of ``S_r`` and of the compensator and ``S_m``.

    Returns
    -------
    SensorModels
        ``S_r``, compensator, ``S_m``, the sensor gain of scheme (b) and provenance.

    Raises
    ------
    ValueError
        If `training` or `training_excitation` is unknown.
    InputError
        ``S_m`` reproduces ``S_r`` (max difference < 1e-6 in normalised units), or a family
        name is unknown.
    """
    if training not in TRAININGS:
        raise ValueError(f"training must be one of {TRAININGS}, got {training!r}")
    if model_cells is None and model == "mpl":
        model_cells = 3 if training == "recording" else 1
    if sensor is not None:
        s_r, sensor_source = sensor, sensor.info.get("source", sensor.name)
    else:
        if sensor_cells is None and sensor_model == "mpl":
            sensor_cells = 3
        rec_r = simulate_experiment("noise", sensor_seed) if sensor_recording is None \
            else sensor_recording
        s_r = fit_forward_sensor(rec_r, sensor_cells, model=sensor_model, name="S_r")
        sensor_source = rec_r.source
    if training_recording is not None:
        rec_t = training_recording
    elif training == "recording":
        rec_t = simulate_experiment(training_excitation, training_seed)
    else:
        dt = s_r.info.get("fit_dt", s_r.structure.dt if s_r.structure is not None else 0.025)
        t = np.arange(round(200.0 / dt)) * dt
        position = 3.0 * np.sin(np.pi * t)  # mm, eq. 7.3
        signal, _ = s_r.simulate(position * MM, dt)
        rec_t = Recording(time=t, position=position, sensor=signal,
                          source="<S_r on 3 mm sin(pi t), 200 s>")
    comp = fit_compensator(rec_t, model_cells, model=model, mode="direct", center="fit")
    s_m = fit_forward_sensor(rec_t, model_cells, model=model, name="S_m")
    if training == "loop":
        p = rec_t.position * MM
        gap = np.max(np.abs(s_m.simulate(p, rec_t.dt)[0] - rec_t.sensor)) / s_m.out_scale
        if gap < 1e-6:
            raise InputError(f"S_m reproduces S_r exactly (max difference {gap:.1e}): identical "
                             f"models make an unrealistic identity (sec. 6.2.2); use a smaller "
                             f"model than the sensor's")
    info = {"training": training, "sensor_source": sensor_source,
            "training_source": rec_t.source, "sensor_model": s_r.info.get("model", "?"),
            "sensor_size": s_r.info.get("size", sensor_cells), "model": model,
            "model_size": s_m.info["size"]}
    return SensorModels(s_r, compensator_block(comp, name="S_m^comp"), s_m,
                        s_m.info["m_per_sensor_unit"], info)


TABLE_II_PREFIX = "table-ii-"
TABLE_II_POSITION_SCALE = 3e-3
"""Assumed position normalisation of paper 9.2's data [m]: the 3 mm stroke of every experiment
(the paper normalises by max |.|, eq. 5.10, but prints no scales)."""


def table_ii_sensors() -> tuple[str, ...]:
    """Columns of paper 9.2's table II that can run as ``S_r`` (the mpl-poly family's presets).

    Returns
    -------
    tuple of str
        Column names accepted by :func:`table_ii_sensor`.
    """
    presets = get_family("mpl-poly").presets()
    return tuple(k.removeprefix(TABLE_II_PREFIX) for k in presets if k.startswith(TABLE_II_PREFIX))


def table_ii_sensor(column: str = "noise", *, sensor_scale: float = 1.0,
                    sensor_offset: float = 0.0) -> SensorBlock:
    """Paper 9.2's table II ``column`` as the forward "real" sensor ``S_r``: position -> sensor.

    The column is a *direct compensator* fitted sensor -> position on normalised 40 Hz data
    (N = 1). As a sensor it runs backwards: the block is the model's inverse (``inverse=True``),
    position normalised by :data:`TABLE_II_POSITION_SCALE` in, the model's normalised sensor
    out -- the signal whose compensator the column is. ``sensor_scale`` and ``sensor_offset``
    only choose the sensor's physical units (default: the normalised sensor itself, which spans
    about +-1 on full-range motion, as the paper's normalised data did; docs/control.md).

    Parameters
    ----------
    column : str, default "noise"
        One of :func:`table_ii_sensors`.
    sensor_scale : float, default 1.0
        Sensor units per normalised sensor unit.
    sensor_offset : float, default 0.0
        Sensor signal at normalised zero [sensor units].

    Returns
    -------
    SensorBlock
        Position [m] in, sensor signal out.

    Raises
    ------
    ValueError
        If `column` is not a column of table II.
    """
    presets = get_family("mpl-poly").presets()
    key = TABLE_II_PREFIX + column
    if key not in presets:
        raise ValueError(f"table II has columns {sorted(table_ii_sensors())}, got {column!r}")
    structure, params, source = presets[key]
    return SensorBlock(structure, params, True, 0.0, TABLE_II_POSITION_SCALE, sensor_offset,
                       sensor_scale, name="S_r",
                       info={"source": source.get("source", key), "model": "mpl-poly",
                             "direction": "position -> sensor (inverse of a sensor -> position "
                             "fit)", "size": 1, "fit_dt": structure.dt,
                             "position_scale_m": TABLE_II_POSITION_SCALE,
                             "sensor_scale": sensor_scale})


def virtual_sensor_block(sensor: VirtualSensor | None = None, *,
                         name: str = "S_r") -> SensorBlock:
    """The virtual sensor's own causal physics as the "real" sensor ``S_r``.

    Position [m] in, ``dR1/R1 - dR2/R2`` out, the units of its recordings
    (:mod:`hystkit.sensors._loop_model`).

    The stand-in for the FEM model the document lacked (ch. 6): a compensator fitted on
    :func:`~hystkit.sensors.simulate_experiment` recordings meets the sensor itself, not a model
    of it. Deterministic (no noise, temperature or settling); ``fit_dt`` is the recordings'
    rate, at which ``fit_sensor_models(training="loop")`` runs it.

    Parameters
    ----------
    sensor : VirtualSensor, optional
        The simulated sensor; default :class:`~hystkit.sensors.VirtualSensor` ().
    name : str, default "S_r"
        Block name.

    Returns
    -------
    SensorBlock
        Position [m] in, sensor signal out.
    """
    sensor = VirtualSensor() if sensor is None else sensor
    structure, params = physics_of(sensor)
    return SensorBlock(structure, params, False, 0.0, MM, 0.0, 1.0, name=name,
                       info={"source": "<virtual sensor physics: steps 1-4, causal>",
                             "model": VIRTUAL_PHYSICS.name, "direction": "position -> sensor",
                             "size": structure.n_state, "fit_dt": 1.0 / sensor.fs_out},
                       model_family=VIRTUAL_PHYSICS)
