"""Sensor blocks for the loop: fitted hysteresis models of any family in physical units.

The fits that make them (and the ready-made sensors) are in ``_sensors.py``.

A :class:`SensorBlock` wraps a fitted model of any registered family (``hystkit.models``) with
the affine maps between the loop's physical units and the normalised units the model was fitted
in (eq. 5.10)::

    u_norm = (input - in_offset) / in_scale        # metres or sensor units in
    output = out_scale * model(u_norm) + out_offset

- the "real" sensor ``S_r`` maps plant position [m] to the sensor signal; it is a *forward*
  model fitted position -> sensor (:func:`~hystkit.control.fit_forward_sensor`), or a model
  file run in the position -> sensor direction (:func:`sensor_block`);
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

from .._docfill import docfiller
from ..compensation import Compensator, Scaling
from ..models import Family, family_of
from . import _kernel

__all__ = ["MM", "SensorBlock", "SensorModels", "compensator_block", "forward_block",
           "linear_block", "sensor_block"]

MM = 1e-3  # recordings hold position in mm; the loop works in metres

# What the builders of a sensor block take and return (%(compensator)s, %(sensor_block)s).
SENSOR_BLOCK_ENTRIES = {
    "sensor_block": """Returns
-------
SensorBlock
    Position [m] in, sensor signal out.""",
    # the model file the compensator and sensor blocks run
    "compensator": """compensator : Compensator
    A fitted compensator (a model file).""",
}
fill_sensor_doc = docfiller(SENSOR_BLOCK_ENTRIES.__getitem__)


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


@fill_sensor_doc
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

    %(sensor_block)s
    """
    return SensorBlock(structure, params, False, scaling.position_offset * MM,
                       scaling.position_scale * MM, scaling.sensor_offset, scaling.sensor_scale,
                       name=name, info=dict(info or {}))


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


@fill_sensor_doc
def compensator_block(compensator: Compensator, *, name: str = "compensator") -> SensorBlock:
    """The compensator as a loop block: sensor signal in, position estimate [m] out.

    Direct mode runs the fitted model; inverse mode runs the inverse of the forward model it
    holds. Offsets: see :func:`_offsets`.

    Parameters
    ----------
    %(compensator)s
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


@fill_sensor_doc
def sensor_block(compensator: Compensator, *, name: str = "S_r") -> SensorBlock:
    """A model file run in the sensor's own direction: position [m] in, sensor signal out.

    An inverse-mode file holds a forward model (position -> sensor): it runs as is. A
    direct-mode file holds sensor -> position: it runs backwards through its family's inverse,
    and a family without one is refused with the reason (``ValueError``).

    Parameters
    ----------
    %(compensator)s
    name : str, default "S_r"
        Block name.

    %(sensor_block)s

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
