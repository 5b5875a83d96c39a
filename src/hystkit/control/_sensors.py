"""Sensor blocks for the loop: fitted hysteresis models in physical units (sec. 7.2-7.3).

A :class:`SensorBlock` wraps a fitted mPL model with the affine maps between the loop's physical
units and the normalised units the model was fitted in (eq. 5.10)::

    u_norm = (input - in_offset) / in_scale        # metres or sensor units in
    output = out_scale * model(u_norm) + out_offset

- the "real" sensor ``S_r`` maps plant position [m] to the sensor signal (dR/R); it is a
  *forward* model fitted position -> sensor (:func:`fit_forward_sensor`);
- the compensator maps the sensor signal to a position estimate [m]
  (:func:`compensator_block`, from a :class:`~hystkit.compensation.Compensator`, direct or
  inverse mode);
- the model ``S_m`` of scheme (b) is another forward model, fitted separately.

Sample time. The mPL is a continuous-time model ``du_k/dt = f_k(e - u_k)`` integrated by forward
Euler (eq. 5.6); it is fitted at the recordings' 40 Hz but runs at the loop's ``Ts`` with the same
``I_S``, ``V_T``, ``w``: the finer step is a more accurate integration of the same ODE. The
Euler slope cap ``slope_cap / dt`` (eq. 5.28-5.29) is an integration limit, so it rises with the
finer step. ``docs/control.md`` quantifies what this changes (R^2 between the 40 Hz and the
``Ts`` runs of the default sensor model: 0.999).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..compensation import Compensator, Scaling, fit_compensator
from ..errors import InputError
from ..io import Recording
from ..models import mpl, mpl_poly
from ..models.mpl import fit_mpl
from ..models.mpl import kernels as mpl_kernels
from ..sensors import simulate_experiment
from . import _poly

__all__ = [
    "BLOCK_HEADER",
    "TRAININGS",
    "SensorBlock",
    "SensorModels",
    "compensator_block",
    "fit_forward_sensor",
    "fit_sensor_models",
    "forward_block",
    "linear_block",
    "table_ii_sensor",
]

BLOCK_HEADER = 10
"""Packed block layout for the kernel: ``[n, inverse, v_b, cap, dt, a_in, b_in, a_out, b_out,
kind, ...]``; the affine maps are ``u_norm = a_in u + b_in`` and ``out = a_out y_norm + b_out``.
``kind`` 0, the sinh mPL: ``i_s (n), v_t (n), knee (n), w (n + 1)`` follow; ``kind`` 1, the
polynomial mPL: the body of :func:`hystkit.control._poly.pack_body`."""

MM = 1e-3  # recordings hold position in mm; the loop works in metres


@dataclass(frozen=True, eq=False)
class SensorBlock:
    """A fitted mPL model between physical signals; pure, state passed in and out.

    Parameters
    ----------
    structure : MplStructure or MplPolyStructure
        As fitted (its ``dt`` is the fitting sample time; the loop re-runs it at ``Ts``).
    params : MplParams or MplPolyParams
        The sinh mPL (eq. 5.2) or the polynomial mPL (eq. 5.16-5.17, :mod:`._poly`).
    inverse : bool
        Run the analytical inverse (eq. 5.13-5.14) instead of the model itself (a compensator
        fitted in inverse mode).
    in_offset, in_scale : float
        Input normalisation, input units (m for a sensor, sensor units for a compensator).
    out_offset, out_scale : float
        Output de-normalisation, output units.
    name : str
    info : dict
        Provenance: training source, fit cost and R^2 (free-form, JSON-safe).
    """

    structure: mpl.MplStructure | mpl_poly.MplPolyStructure
    params: mpl.MplParams | mpl_poly.MplPolyParams
    inverse: bool = False
    in_offset: float = 0.0
    in_scale: float = 1.0
    out_offset: float = 0.0
    out_scale: float = 1.0
    name: str = "model"
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.is_poly != isinstance(self.structure, mpl_poly.MplPolyStructure):
            raise ValueError("structure and params belong to different model families")
        if self.params.n_cells != self.structure.n_cells:
            raise ValueError(f"params have {self.params.n_cells} cells, structure has "
                             f"{self.structure.n_cells}")
        for key in ("in_offset", "in_scale", "out_offset", "out_scale"):
            if not np.isfinite(getattr(self, key)):
                raise ValueError(f"{key} must be finite")
        if self.in_scale == 0 or self.out_scale == 0:
            raise ValueError("in_scale and out_scale must be non-zero")
        if self.inverse and self.params.w[0] == 0:
            raise ValueError("an inverse block needs w_0 != 0 (eq. 5.13)")

    @property
    def n_cells(self) -> int:
        return self.structure.n_cells

    @property
    def is_poly(self) -> bool:
        """True for the polynomial mPL (``mpl-poly``), False for the sinh mPL."""
        return isinstance(self.params, mpl_poly.MplPolyParams)

    def at(self, dt: float):
        """The model's structure re-stepped at ``dt`` (same cells, slope cap and limit)."""
        if self.is_poly:
            return mpl_poly.MplPolyStructure(self.structure.n_cells, dt,
                                             self.structure.slope_cap, self.structure.limit)
        return mpl.MplStructure(self.structure.n_cells, dt, self.structure.slope_cap)

    def rest_state(self, u_in: float) -> np.ndarray:
        """Cell voltages at rest for a constant input ``u_in`` (each cell equals its drive).

        Forward: the cells' drive is the normalised input. Inverse: the drive is the input
        estimate, and at rest ``u_hat = (y + V_b) / sum(w)``, as :func:`mpl.invert` starts.
        """
        v = (u_in - self.in_offset) / self.in_scale
        if self.is_poly:
            return _poly.rest_state(self.structure, self.params, self.inverse, float(v))
        if self.inverse:
            w_sum = float(np.sum(self.params.w))
            v = (v + self.params.v_b) / w_sum if w_sum != 0 else 0.0
        return np.full(self.n_cells, float(v))

    def step(self, x: np.ndarray, u_in: float, dt: float) -> tuple[float, np.ndarray]:
        """One sample (readable reference): output from the present state, then the update."""
        u = (u_in - self.in_offset) / self.in_scale
        structure = self.at(dt)
        if self.is_poly:
            y, x_next = _poly.step(structure, self.params, self.inverse, x, u)
        elif self.inverse:
            y, x_next = mpl.invert_step(structure, self.params, x, u)
        else:
            y, x_next = mpl.step(structure, self.params, x, u)
        return self.out_scale * y + self.out_offset, x_next

    def simulate(self, u_in: np.ndarray, dt: float,
                 x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Run the block open loop over ``u_in`` (physical units) at sample time ``dt``.

        Returns
        -------
        out : array, shape (n,)
        x_end : array, shape (N,)
        """
        u_in = np.asarray(u_in, dtype=float)
        x0 = self.rest_state(float(u_in[0])) if x0 is None else x0
        u = (u_in - self.in_offset) / self.in_scale
        if self.is_poly:
            y, x_end = _poly.simulate(self.at(dt), self.params, self.inverse, u, x0)
        else:
            run = mpl.invert if self.inverse else mpl.simulate
            y, x_end = run(self.at(dt), self.params, u, x0)
        return self.out_scale * y + self.out_offset, x_end

    def pack(self, dt: float) -> np.ndarray:
        """Flat float64 array for the compiled loop (layout :data:`BLOCK_HEADER`)."""
        s = self.at(dt)
        p = self.params
        header = [p.n_cells, float(self.inverse), p.v_b, s.slope_cap / dt, dt,
                  1.0 / self.in_scale, -self.in_offset / self.in_scale, self.out_scale,
                  self.out_offset, float(self.is_poly)]
        if self.is_poly:
            return np.concatenate([header, _poly.pack_body(s, p)]).astype(np.float64)
        knee = mpl.knee_voltage(s, p)
        return np.concatenate([header, p.i_s, p.v_t, knee, p.w]).astype(np.float64)

    def linearise(self, x: np.ndarray, u_in: float,
                  dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Discrete linearisation ``(A, B, C, D)`` at state ``x`` and input ``u_in``.

        Paper 9.2 eq. 2-7: each cell ``x+ = x + f(v) dt`` with ``v`` its drive minus ``x``
        becomes ``dx+ = (1 - f' dt) dx + f' dt d(drive)``, with ``f'`` the slope of the
        *limited* resistor (eq. 5.29) at the operating point.
        """
        x = np.asarray(x, dtype=float)
        u = (u_in - self.in_offset) / self.in_scale
        if self.is_poly:
            a, b, c, d = _poly.linearise(self.at(dt), self.params, self.inverse, x, u)
            return (a, b / self.in_scale, self.out_scale * c,
                    self.out_scale * d / self.in_scale)
        p = self.params
        s = self.at(dt)
        knee = mpl.knee_voltage(s, p)
        w, w0 = p.w[1:], p.w[0]
        drive = (u + p.v_b - w @ x) / w0 if self.inverse else u
        slope = np.array([mpl_kernels.current(drive - x[k], p.i_s[k], p.v_t[k], knee[k],
                                               s.slope_cap / dt)[1] for k in range(p.n_cells)])
        g = slope * dt
        if self.inverse:
            # drive = (u - w.x + V_b) / w0 feeds back into every cell
            a = np.diag(1.0 - g) - np.outer(g, w) / w0
            b, c, d = g / w0, -w / w0, 1.0 / w0
        else:
            a, b, c, d = np.diag(1.0 - g), g, w.copy(), w0
        return (a, b / self.in_scale, self.out_scale * c, self.out_scale * d / self.in_scale)


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


def forward_block(structure: mpl.MplStructure, params: mpl.MplParams, scaling: Scaling, *,
                  name: str = "sensor", info: dict | None = None) -> SensorBlock:
    """Forward model position [m] -> sensor from a fit on normalised mm data."""
    return SensorBlock(structure, params, False, scaling.position_offset * MM,
                       scaling.position_scale * MM, scaling.sensor_offset, scaling.sensor_scale,
                       name=name, info=dict(info or {}))


def fit_forward_sensor(recording: Recording, n_cells: int = 3, *, slope_cap: float = 1.0,
                       name: str = "sensor") -> SensorBlock:
    """Fit a forward mPL (position -> sensor, the sensor's own direction) on a recording.

    ``fit_mpl(position_norm, sensor_norm)`` on the recording centred on its means and scaled by
    its max |.| (eq. 5.10). ``info`` records the source, the SSE, the R^2 on the fitting data
    and the straight-line gain ``position per sensor unit`` [m / sensor unit], which scheme (b)
    uses to express the sensor error in metres.
    """
    if not recording.has_position():
        raise InputError(f"{recording.source}: column 'position' is needed to fit a sensor")
    scaling, s, p = _normalise(recording)
    structure = mpl.MplStructure(n_cells, recording.dt, slope_cap)
    result = fit_mpl(p, s, structure)
    y, _ = mpl.simulate(structure, result.params, p)
    gain = np.polyfit(recording.sensor, recording.position * MM, 1)[0]
    info = {"source": recording.source, "direction": "position -> sensor", "n_cells": n_cells,
            "fit_dt": recording.dt, "sse": result.cost, "r2": _r2(y, s),
            "fit_seconds": result.seconds, "m_per_sensor_unit": float(gain)}
    return forward_block(structure, result.params, scaling, name=name, info=info)


def compensator_block(compensator: Compensator, *, name: str = "compensator") -> SensorBlock:
    """The compensator as a loop block: sensor signal in, position estimate [m] out.

    A loop has no recording mean to remove, so the *fitting* recording's offsets are used for
    every centring choice except ``none`` (whose offsets are zero) -- the ``fit`` centring of
    :mod:`hystkit.compensation`. Direct mode runs the fitted model; inverse mode runs the
    analytical inverse of the forward model it holds.
    """
    sc = compensator.scaling
    s_off, p_off = (0.0, 0.0) if compensator.center == "none" else (sc.sensor_offset,
                                                                    sc.position_offset)
    info = {k: v for k, v in compensator.fit_info.items()
            if isinstance(v, str | int | float | bool)}
    info.update(mode=compensator.mode, direction="sensor -> position")
    return SensorBlock(compensator.structure, compensator.params,
                       compensator.mode == "inverse", s_off, sc.sensor_scale,
                       p_off * MM, sc.position_scale * MM, name=name, info=info)


def linear_block(gain: float, offset: float = 0.0, *, name: str = "linear") -> SensorBlock:
    """An ideal, memoryless linear block ``out = gain * input + offset``.

    Built as an mPL whose single cell has zero weight, so it runs through the same compiled code
    as the fitted models (the property tests' ideal sensor and exact compensator).
    """
    if not (np.isfinite(gain) and gain != 0):
        raise ValueError(f"gain must be finite and non-zero, got {gain!r}")
    params = mpl.MplParams(i_s=[1e-3], v_t=[1.0], w=[1.0, 0.0], v_b=0.0)
    return SensorBlock(mpl.MplStructure(1, 1.0), params, False, 0.0, 1.0, float(offset),
                       float(gain), name=name, info={"kind": "ideal linear", "gain": gain})


TRAININGS = ("recording", "loop")


@dataclass(frozen=True, eq=False)
class SensorModels:
    """The three models of ch. 7, fitted separately (never one object twice, sec. 6.2.2).

    Attributes
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
    """

    sensor: SensorBlock
    compensator: SensorBlock
    model: SensorBlock
    sensor_gain: float
    info: dict = field(default_factory=dict)


def fit_sensor_models(*, training: str = "recording", sensor_cells: int = 3,
                      model_cells: int | None = None, sensor_seed: int = 1,
                      training_seed: int = 2, training_excitation: str = "sine",
                      sensor_recording: Recording | None = None,
                      training_recording: Recording | None = None,
                      sensor: SensorBlock | None = None) -> SensorModels:
    """Fit ``S_r``, the compensator and ``S_m`` as the document's ch. 7 does (about 2 s).

    ``S_r`` is a forward mPL fitted on the sensor recording (default: the virtual sensor's noise
    experiment, seed ``sensor_seed``: the document's choice of the noise-trained model as the
    real sensor, fig. 7.2). The compensator (direct mode, sensor -> position) and ``S_m``
    (forward) come from separate training data:

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
    sensor_cells, model_cells : int
        mPL cells of ``S_r`` and of the compensator / ``S_m`` (default 3 for ``recording``,
        1 for ``loop``).
    sensor_recording, training_recording : Recording, optional
        Use these instead of the virtual sensor's.
    sensor : SensorBlock, optional
        A ready ``S_r`` (e.g. :func:`table_ii_sensor`) instead of a fit; its ``fit_dt`` is the
        rate of the ``loop`` training run.

    Raises
    ------
    InputError
        ``S_m`` reproduces ``S_r`` (max difference < 1e-6 in normalised units).
    """
    if training not in TRAININGS:
        raise ValueError(f"training must be one of {TRAININGS}, got {training!r}")
    model_cells = (3 if training == "recording" else 1) if model_cells is None else model_cells
    if sensor is not None:
        s_r, sensor_source = sensor, sensor.info.get("source", sensor.name)
        sensor_cells = sensor.n_cells
    else:
        rec_r = simulate_experiment("noise", sensor_seed) if sensor_recording is None \
            else sensor_recording
        s_r, sensor_source = fit_forward_sensor(rec_r, sensor_cells, name="S_r"), rec_r.source
    if training_recording is not None:
        rec_t = training_recording
    elif training == "recording":
        rec_t = simulate_experiment(training_excitation, training_seed)
    else:
        dt = s_r.structure.dt
        t = np.arange(round(200.0 / dt)) * dt
        position = 3.0 * np.sin(np.pi * t)  # mm, eq. 7.3
        sensor, _ = s_r.simulate(position * MM, dt)
        rec_t = Recording(time=t, position=position, sensor=sensor,
                          source="<S_r on 3 mm sin(pi t), 200 s>")
    comp = fit_compensator(rec_t, model_cells, mode="direct", center="fit")
    s_m = fit_forward_sensor(rec_t, model_cells, name="S_m")
    if training == "loop":
        p = rec_t.position * MM
        gap = np.max(np.abs(s_m.simulate(p, rec_t.dt)[0] - rec_t.sensor)) / s_m.out_scale
        if gap < 1e-6:
            raise InputError(f"S_m reproduces S_r exactly (max difference {gap:.1e}): identical "
                             f"models make an unrealistic identity (sec. 6.2.2); use fewer "
                             f"model cells than the sensor's {sensor_cells}")
    info = {"training": training, "sensor_source": sensor_source,
            "training_source": rec_t.source, "sensor_cells": sensor_cells,
            "model_cells": model_cells}
    return SensorModels(s_r, compensator_block(comp, name="S_m^comp"), s_m,
                        s_m.info["m_per_sensor_unit"], info)


def table_ii_sensor(column: str = "noise") -> SensorBlock:
    """Paper 9.2's table II ``column`` as ``S_r``: the inverse of that sensor -> position fit.

    Position [m] in (normalised by the assumed 3 mm), the paper's normalised sensor out (spans
    about +-1 on full-range motion). See :func:`hystkit.control._poly.table_ii_block` and
    docs/control.md section 2.
    """
    return _poly.table_ii_block(column)
