"""The synchronisation excitation e_sync (eq. 2.21-2.22): a known model state to start from.

A hysteresis model remembers its input history, and at power-on nobody knows the device's. The
document (after its ref. [4]) drives the Power-Law circuit with a step of ``2 N V_T``
(eq. 2.21: from ``E_0`` down to ``E_0 - 2 N V_T``; eq. 2.22 the mirror image): every cell
``k`` of threshold ``k V_T`` then sits at ``E_0 - (2N - k) V_T`` whatever its state before, so
model and compensator start together.

What is built here, for every family:

- **play-operator families** (``pl``, ``ladder``): eq. 2.21 as written, with
  ``E_0 = N V_T`` (the smallest ``E_0`` it allows): levels ``+A, -A`` with ``A`` the largest
  threshold (``N V_T``; for the ladder's play operators in series, the sum of the dead bands),
  then back to rest (normalised input 0) so that a stream starts where the device rests;
- **every other family** (a generalisation, not in the document): the same three levels with
  ``A = 1``, a swing to both ends of the normalised training range (eq. 5.10) and back to rest.

Each level is held for the same time, the shortest (doubling from ``min_hold_seconds``) after
which the model's state no longer depends on the history before it: the excitation is run from
``n_histories`` different prior histories (random walks over the training range and rests at
its ends) and their final states must agree to ``tolerance``. A family whose state does not
converge within ``max_seconds`` is refused with the spread it kept.

The signal is the *model input*: the position for an ``inverse`` compensator (its forward model
runs position -> sensor; move the device through it), the sensor for a ``direct`` one (move the
device until the sensor reads the levels; or simply stream the sync itself from ``start="rest"``,
since after it the state no longer depends on where the stream started).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..compensation import Compensator
from ..errors import InputError

__all__ = ["SyncExcitation", "sync_excitation"]

DEFAULT_TOLERANCE = 1e-6
DEFAULT_MAX_SECONDS = 600.0
DEFAULT_MIN_HOLD_SECONDS = 0.5

@dataclass(frozen=True, eq=False)
class SyncExcitation:
    """A synchronisation excitation and the model state it leaves.

    Parameters
    ----------
    quantity : {"position", "sensor"}
        What is applied: the position for an inverse compensator, the sensor for a direct one.
    unit : str
        ``"mm"`` or ``"sensor units"`` (at the training data's offsets).
    signal : array, shape (n,)
        The excitation in ``unit``, one value per sample ``dt``.
    normalised : array, shape (n,)
        The same as the model's (normalised, eq. 5.10) input.
    dt : float
        Sample time [s].
    levels : tuple of float
        Normalised levels held in turn.
    hold_seconds : float
        How long each level is held.
    rule : str
        Which construction was used (module docstring).
    state_after : array
        Model state at the end (the compensator's state vector: start a stream from it).
    spread : float
        Largest difference between the final states reached from the different prior
        histories (normalised units), at most ``tolerance * max(1, max|state_after|)``.
    tolerance : float
    """

    quantity: str
    unit: str
    signal: np.ndarray
    normalised: np.ndarray
    dt: float
    levels: tuple[float, ...]
    hold_seconds: float
    rule: str
    state_after: np.ndarray
    spread: float
    tolerance: float

    def __post_init__(self) -> None:
        for name in ("signal", "normalised", "state_after"):
            value = np.array(getattr(self, name), dtype=np.float64)
            value.flags.writeable = False
            object.__setattr__(self, name, value)

    @property
    def duration(self) -> float:
        """Length of the excitation [s]."""
        return self.signal.size * self.dt


def sync_excitation(comp: Compensator, *, tolerance: float = DEFAULT_TOLERANCE,
                    max_seconds: float = DEFAULT_MAX_SECONDS,
                    min_hold_seconds: float = DEFAULT_MIN_HOLD_SECONDS,
                    n_histories: int = 6, seed: int = 0) -> SyncExcitation:
    """Build e_sync for ``comp`` and the state it leaves (module docstring).

    Parameters
    ----------
    comp : Compensator
        The compensator to synchronise.
    tolerance : float, default 1e-6
        Largest spread of the final states, relative to ``max(1, max|state|)``.
    max_seconds : float, default 600.0
        Longest hold [s] tried before giving up.
    min_hold_seconds : float, default 0.5
        First hold [s] tried; doubled until the states agree.
    n_histories : int, default 6
        Prior histories the excitation is run from.
    seed : int, default 0
        Seed of the random prior histories.

    Returns
    -------
    SyncExcitation
        The excitation, its levels and hold, and the state it leaves.

    Raises
    ------
    InputError
        If the model's state still depends on its history after holds of ``max_seconds``
        (name, spread reached): start such a model at rest or from a saved state.
    """
    dt = comp.structure.dt
    amplitude, rule = _amplitude(comp)
    levels = (amplitude, -amplitude, 0.0)
    priors = _prior_states(comp, n_histories, seed)
    n_hold = max(1, round(min_hold_seconds / dt))
    while True:
        v = np.repeat(levels, n_hold)
        ends = [_run(comp, v, x0) for x0 in priors]
        scale = max(1.0, float(np.max(np.abs(ends[0]))))
        spread = max(float(np.max(np.abs(end - ends[0]))) for end in ends)
        if spread <= tolerance * scale:
            break
        if 2 * n_hold * dt * len(levels) > max_seconds:
            raise InputError(
                f"{comp.source or 'compensator'}: the {comp.model} model still remembers its "
                f"history after a synchronisation excitation of {v.size * dt:g} s (final states "
                f"from different histories differ by {spread:.3g}, tolerance "
                f"{tolerance * scale:.3g}); start it at rest or from a saved state")
        n_hold *= 2
    quantity, unit, signal = _in_user_units(comp, v)
    return SyncExcitation(quantity=quantity, unit=unit, signal=signal, normalised=v, dt=dt,
                          levels=levels, hold_seconds=n_hold * dt, rule=rule,
                          state_after=ends[0], spread=spread, tolerance=tolerance)


def _amplitude(comp: Compensator) -> tuple[float, str]:
    amplitude = comp.family.capabilities.sync_amplitude
    if amplitude is not None:  # families of play operators: their largest threshold
        return float(amplitude(comp.structure, comp.params)), (
            "eq. 2.21 with E_0 = N V_T (largest play threshold), then back to rest")
    return 1.0, "swing to both ends of the training range (max |.| = 1), then back to rest"


def _prior_states(comp: Compensator, n_histories: int, seed: int) -> list[np.ndarray]:
    """Model states after different histories: rest at 0 (the reference), rests at the ends
    of the training range, then random walks over it."""
    family, structure, params = comp.family, comp.structure, comp.params
    rests = [family.rest_state(structure, params, v) for v in (0.0, 1.0, -1.0)]
    rng = np.random.default_rng(seed)
    n = max(50, round(5.0 / structure.dt))
    walks = []
    for _ in range(max(0, n_histories - len(rests))):
        u = np.clip(np.cumsum(rng.normal(0.0, 0.2, n)), -1.2, 1.2)
        walks.append(family.simulate(structure, params, u)[1])
    return (rests + walks)[:max(2, n_histories)]


def _run(comp: Compensator, v: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """State the model reaches when its input follows ``v`` from ``x0``. An inverse
    compensator's state is its forward model's (every family's ``invert`` carries the forward
    state), which the excitation drives as eq. 2.21 drives the actuator's model."""
    with np.errstate(over="ignore", invalid="ignore"):
        _, x_end = comp.family.simulate(comp.structure, comp.params, v, np.array(x0))
    return np.asarray(x_end, dtype=np.float64)


def _in_user_units(comp: Compensator, v: np.ndarray) -> tuple[str, str, np.ndarray]:
    if comp.mode == "inverse":
        return "position", "mm", v * comp.scaling.position_scale + comp.position_offset()
    sensor = v * comp.scaling.sensor_scale / comp.polarity + comp.scaling.sensor_offset
    return "sensor", "sensor units", sensor
