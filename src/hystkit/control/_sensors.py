"""The sensor models of ch. 7, fitted: ``S_r``, the compensator and ``S_m`` (:func:`fit_sensor_models`),
a forward sensor on any recording (:func:`fit_forward_sensor`), and the ready-made sensors: paper
9.2's table II (:func:`table_ii_sensor`) and the virtual sensor's own physics
(:func:`virtual_sensor_block`). The blocks they return: ``_sensor_blocks.py``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..compensation import Scaling, fit_compensator
from ..errors import InputError
from ..io import Recording
from ..models import get_family
from ..sensors import VIRTUAL_PHYSICS, VirtualSensor, physics_of, simulate_experiment
from ._names import TRAININGS
from ._sensor_blocks import (
    MM,
    SensorBlock,
    SensorModels,
    compensator_block,
    fill_sensor_doc,
    forward_block,
)

__all__ = ["TRAININGS", "fit_forward_sensor", "fit_sensor_models", "table_ii_sensor",
           "table_ii_sensors", "virtual_sensor_block"]


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


@fill_sensor_doc
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

    %(sensor_block)s

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


@fill_sensor_doc
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

    %(sensor_block)s
    """
    sensor = VirtualSensor() if sensor is None else sensor
    structure, params = physics_of(sensor)
    return SensorBlock(structure, params, False, 0.0, MM, 0.0, 1.0, name=name,
                       info={"source": "<virtual sensor physics: steps 1-4, causal>",
                             "model": VIRTUAL_PHYSICS.name, "direction": "position -> sensor",
                             "size": structure.n_state, "fit_dt": 1.0 / sensor.fs_out},
                       model_family=VIRTUAL_PHYSICS)
