"""A loop from its description: what ``hystkit control`` and ``hystkit stability --control`` set
up before they run or examine it (:func:`setup_loop`).

A :class:`LoopSetup` names everything that defines the loop: the scheme, the controller and
plant, where ``S_r`` comes from (fitted on the virtual sensor or a recording, the virtual
sensor's physics, a column of paper 9.2's table II, a model file), the families and sizes of
the fitted models and their training data, and model files that replace the fitted compensator
or ``S_m``. The sensor models are fitted once and kept on disk (``_disk_cache.py``).

What only some setups need is looked up in the package when needed (its lazy table): the
virtual sensor and the fits (scipy.signal, 0.6 s to import), the PID tuning and DOB design
(python-control, 0.6 s), which a loop read from the cache with the document's gains never uses.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

from .. import control as package
from .._docfill import docfiller
from ..compensation import Compensator
from ..io import Recording
from ._blocks import PID, DisturbanceObserver, Plant
from ._disk_cache import cached_sensor_models
from ._experiments import build_loop
from ._loop import ControlLoop
from ._names import MASS
from ._sensor_blocks import SensorBlock, SensorModels, compensator_block, sensor_block

__all__ = ["LoopError", "LoopSetup", "SetupResult", "sensor_from", "setup_loop"]

# The Parameters section of the functions of a loop's definition (%(setup_parameters)s).
SETUP_ENTRIES = {
    "setup_parameters": """Parameters
----------
setup : LoopSetup
    The loop's definition.""",
}
fill_setup_doc = docfiller(SETUP_ENTRIES.__getitem__)

TABLE_II = "table-ii-"


class LoopError(ValueError):
    """A part of the setup that cannot serve.

    Parameters
    ----------
    part : {"sensor", "compensator", "model", "loop"}
        Which part: ``"model"`` is the model file of ``S_m``, ``"loop"`` the combination.
    message : str
        What is wrong, one line.
    """

    def __init__(self, part: str, message: str) -> None:
        super().__init__(message)
        self.part = part


@dataclass(frozen=True)
class LoopSetup:
    """Everything that defines a loop of ``hystkit control``.

    Parameters
    ----------
    scheme : {"direct", "weighting"}
    sensor : str, default "virtual"
        ``S_r``: ``virtual`` (a model fitted on the virtual sensor's noise run, or on
        `sensor_recording`), ``virtual-physics``, ``table-ii-COLUMN``; a model file is given
        as `sensor_file` instead.
    sensor_file : Compensator, optional
        A model file run position -> sensor as ``S_r``.
    sensor_model, model : str, default "mpl"
        Families of the fitted ``S_r`` and of the fitted compensator and ``S_m``.
    sensor_size, model_size : int, optional
        Their sizes (None: :func:`~hystkit.control.fit_sensor_models`' defaults).
    training : {"recording", "loop"}, optional
        Training data of the compensator and ``S_m``; default ``recording`` with a virtual
        sensor, else ``loop``.
    training_excitation : str, default "sine"
    sensor_recording, training_recording : Recording, optional
        Recordings to fit ``S_r`` and the compensator / ``S_m`` on.
    compensator, model_file : Compensator, optional
        Model files that replace the fitted compensator and ``S_m``.
    pid : PID, optional
        Default: the document's gains for the scheme.
    tune : (float, float), optional
        Crossover [Hz] and phase margin [deg] for :func:`~hystkit.control.tune_pid`.
    tf : float, default 0.0
    anti_windup : bool, default False
    mass, u_max : float
    dob : bool, default False
    dob_hz : float, optional
        Q-filter bandwidth; default :func:`~hystkit.control.design_dob`'s.
    zero_at_start : bool, default True
    provenance : dict
        Added to the models' ``info`` (e.g. the model files' names).
    """

    scheme: str
    sensor: str = "virtual"
    sensor_file: Compensator | None = None
    sensor_model: str = "mpl"
    model: str = "mpl"
    sensor_size: int | None = None
    model_size: int | None = None
    training: str | None = None
    training_excitation: str = "sine"
    sensor_recording: Recording | None = None
    training_recording: Recording | None = None
    compensator: Compensator | None = None
    model_file: Compensator | None = None
    pid: PID | None = None
    tune: tuple[float, float] | None = None
    tf: float = 0.0
    anti_windup: bool = False
    mass: float = MASS
    u_max: float = math.inf
    dob: bool = False
    dob_hz: float | None = None
    zero_at_start: bool = True
    provenance: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class SetupResult:
    """The loop built, its sensor models and the seconds they took.

    Parameters
    ----------
    loop : ControlLoop
        The loop, every slot filled.
    models : SensorModels
        The sensor models of ch. 7 it was built from.
    fit_seconds : float
        Seconds the sensor models took, fitted or read from the disk cache.
    """

    loop: ControlLoop
    models: SensorModels
    fit_seconds: float


@fill_setup_doc
def sensor_from(setup: LoopSetup) -> SensorBlock | None:
    """``S_r`` as the setup names it; None for one fitted on the virtual sensor or a recording.

    %(setup_parameters)s

    Returns
    -------
    SensorBlock or None
        The sensor's block, or None when it is fitted.

    Raises
    ------
    LoopError
        ``part="sensor"``: an unknown table II column, or a model file that cannot run as a
        sensor.
    """
    if setup.sensor_file is not None:
        return _block(sensor_block, setup.sensor_file, "S_r", "sensor")
    if setup.sensor == "virtual":
        return None
    if setup.sensor == "virtual-physics":
        return package.virtual_sensor_block()
    column = setup.sensor.removeprefix(TABLE_II)
    columns = package.table_ii_sensors()
    if not setup.sensor.startswith(TABLE_II) or column not in columns:
        raise LoopError("sensor", f"paper 9.2's table II has columns {', '.join(columns)}")
    return package.table_ii_sensor(column)


def _block(make, compensator: Compensator, name: str, part: str) -> SensorBlock:
    try:
        return make(compensator, name=name)
    except ValueError as exc:
        raise LoopError(part, str(exc)) from None


@fill_setup_doc
def setup_loop(setup: LoopSetup) -> SetupResult:
    """The loop of `setup`: its sensor models fitted (or read from the disk cache), model
    files in their slots, the PID tuned and the DOB designed when asked.

    %(setup_parameters)s

    Returns
    -------
    SetupResult
        The loop, its sensor models and the seconds they took.

    Raises
    ------
    LoopError
        A part that cannot serve (its ``part`` says which).
    """
    virtual = setup.sensor in ("virtual", "virtual-physics") and setup.sensor_file is None
    training = setup.training or ("recording" if virtual else "loop")
    t_start = time.perf_counter()
    models = cached_sensor_models(
        sensor=sensor_from(setup), training=training,
        training_excitation=setup.training_excitation, sensor_cells=setup.sensor_size,
        model_cells=setup.model_size, sensor_model=setup.sensor_model, model=setup.model,
        sensor_recording=setup.sensor_recording, training_recording=setup.training_recording)
    if setup.compensator is not None:
        models = replace(models, compensator=_block(compensator_block, setup.compensator,
                                                    "S_m^comp", "compensator"))
    if setup.model_file is not None:
        models = replace(models, model=_block(sensor_block, setup.model_file, "S_m", "model"))
    models = replace(models, info={**models.info, **setup.provenance})
    fit_seconds = time.perf_counter() - t_start
    try:
        return SetupResult(_loop(setup, models), models, fit_seconds)
    except ValueError as exc:
        raise LoopError("loop", str(exc)) from None


def _loop(setup: LoopSetup, models: SensorModels) -> ControlLoop:
    loop = build_loop(setup.scheme, models, pid=setup.pid, plant=Plant(setup.mass, setup.u_max),
                      zero_at_start=setup.zero_at_start)
    pid = setup.pid
    if setup.tune is not None:
        pid = package.tune_pid(setup.tune[0], setup.tune[1], loop=loop)
    loop = replace(loop, pid=replace(pid or loop.pid, tf=setup.tf,
                                     anti_windup=setup.anti_windup))
    if setup.dob:
        dob = (package.design_dob(loop) if setup.dob_hz is None
               else DisturbanceObserver(setup.dob_hz))
        loop = replace(loop, dob=dob)
    loop.kernel_arguments()  # every block at the loop's Ts, or the family's refusal
    return loop
