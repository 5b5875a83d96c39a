"""A fitted compensator: sensor signal in, position estimate out (sec. 5.3.4-5.3.6).

Two ways to get one, for any registered model family (``hystkit.models.FAMILIES``;
the mPL by default):

- ``direct`` (paper 9.2): fit the model from sensor to position; the model *is* the
  compensator.
- ``inverse`` (paper 9.1): fit the forward model position -> sensor and run its inverse
  (for the mPL the analytical eq. 5.13-5.14) on sensor data; only for families with an inverse.

Data pass through the same path at fit and at use: the sensor offset of the centring mode
(:mod:`._centring`; deployable by default), the stored polarity (the sensor is flipped so that
it rises with position, for every family), scaling by the fitting data's max |.| (eq. 5.10), the
model, and back to mm.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np

from .._read_options import ReadOptions
from ..errors import FitDivergedError, InputError
from ..io import Recording
from ..models import Family, get_family
from ._band import Band, interval
from ._centring import (
    CENTERS,
    DEFAULT_TARE_SECONDS,
    DEFAULT_TRACK_SECONDS,
    ORACLE_CENTER,
    sensor_level,
)
from ._conventions import LinearBaseline, Scaling
from ._fit_info import FitInfo
from ._modes import MODES
from ._runaway import MAX_NORMALISED, runaway_kind, runaway_samples

__all__ = [
    "MAX_NORMALISED",
    "MODES",
    "POSITION_MARGIN",
    "SENSOR_MARGIN",
    "BandedEstimate",
    "Compensator",
    "LinearBaseline",
    "Scaling",
    "runaway_kind",
    "runaway_samples",
]

# Use-time guards: a sensor sample is "outside" beyond this share of the training sensor range
# on either side, an estimate beyond this share of the training position range.
SENSOR_MARGIN = 0.05
POSITION_MARGIN = 0.10


class BandedEstimate(NamedTuple):
    """An estimate with its prediction band, all [mm] (:meth:`Compensator.estimate_with_band`).

    Parameters
    ----------
    estimate, lower, upper : numpy.ndarray
    """

    estimate: np.ndarray
    lower: np.ndarray
    upper: np.ndarray


@dataclass(frozen=True, eq=False)
class Compensator:
    """Fitted compensator with its data conventions; apply it with :meth:`estimate`.

    ``model`` names the family in the registry; ``structure`` and ``params`` are that family's
    dataclasses. ``polarity`` (+1 or -1) multiplies the offset-free sensor so that it rises with
    position. ``sensor_reference`` is the training data's sensor level for ``tare`` / ``track``;
    ``rest_position`` [mm] the training position during the tare window; ``position_range``
    [mm] the training position range (use-time guard). ``source`` names the model file it
    was loaded from (for messages; not saved).

    Parameters
    ----------
    structure, params : object
        The family's structure and parameter dataclasses.
    mode : {"direct", "inverse"}
        ``direct``: the model maps sensor -> position; ``inverse``: the model maps position ->
        sensor and its inverse is run on sensor data.
    center : {"fit", "tare", "track", "recording", "none"}
        Where a recording's sensor offset comes from (see :mod:`._centring`).
    scaling : Scaling
        Offsets and scales of the fitting data (eq. 5.10).
    baseline : LinearBaseline
        Straight line position(sensor) in normalised units.
    fit_info : FitInfo or mapping, optional
        What the fit reported (status, scores, settings); a mapping becomes a `FitInfo`.
    model : str, default "mpl"
        Family name in the registry.
    training_range : tuple of float, optional
        Normalised sensor range seen in training (use-time guard).
    polarity : {1.0, -1.0}, default 1.0
        Sign that makes the offset-free sensor rise with position.
    tare_seconds : float, default 2.0
        Length [s] of the tare window.
    track_seconds : float, default 100.0
        Time constant [s] of the ``track`` low-pass.
    sensor_reference : float, default 0.0
        Training sensor level for ``tare`` / ``track`` [sensor units].
    rest_position : float, optional
        Training position [mm] during the tare window.
    position_range : tuple of float, optional
        Training position range [mm].
    source : str, optional
        Model file it was loaded from.
    band : Band, optional
        The calibrated prediction band (:mod:`._band`); None: fitted without one.
    reading : ReadOptions, optional
        How the training recordings were read: their column names, time unit, units line and
        units (only these fields; the others are left at their defaults). Later commands read
        a file of the same column names this way by default. None: not known (fitted on
        arrays, on files read differently, or by a hystkit before it was kept).

    Raises
    ------
    ValueError
        An unknown mode or centring, an inverse mode for a family without an inverse, params
        that do not fit the structure, or a non-finite / non-positive scaling, baseline,
        polarity, window or range.
    """

    structure: Any
    params: Any
    mode: str
    center: str
    scaling: Scaling
    baseline: LinearBaseline
    fit_info: FitInfo = field(default_factory=FitInfo)
    model: str = "mpl"
    training_range: tuple[float, float] | None = None
    polarity: float = 1.0
    tare_seconds: float = DEFAULT_TARE_SECONDS
    track_seconds: float = DEFAULT_TRACK_SECONDS
    sensor_reference: float = 0.0
    rest_position: float | None = None
    position_range: tuple[float, float] | None = None
    source: str | None = field(default=None, compare=False)
    band: Band | None = None
    reading: ReadOptions | None = None

    @property
    def family(self) -> Family:
        return get_family(self.model)

    def __post_init__(self) -> None:
        if self.mode not in MODES or self.center not in CENTERS:
            raise ValueError(f"unknown mode/center {self.mode!r}/{self.center!r}")
        if self.mode == "inverse" and self.family.invert is None:
            raise ValueError(f"model {self.model!r} has no inverse "
                             f"({self.family.no_inverse_reason})")
        # A two-sample run makes the family check that structure and params belong together.
        self.family.simulate(self.structure, self.params, np.zeros(2))
        for name, value in vars(self.scaling).items():
            ok = np.isfinite(value) and (value > 0 if name.endswith("scale") else True)
            if not ok:
                raise ValueError(f"normalisation {name} must be finite"
                                 f"{' and positive' if name.endswith('scale') else ''}, "
                                 f"got {value}")
        if not (np.isfinite(self.baseline.slope) and np.isfinite(self.baseline.intercept)):
            raise ValueError("baseline slope and intercept must be finite")
        if self.polarity not in (1.0, -1.0):
            raise ValueError(f"polarity must be +1 or -1, got {self.polarity!r}")
        if not (self.tare_seconds > 0 and self.track_seconds > 0):
            raise ValueError("tare_seconds and track_seconds must be positive")
        for name in ("training_range", "position_range"):
            value = getattr(self, name)
            if value is not None:
                lo, hi = (float(v) for v in value)
                if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
                    raise ValueError(f"{name} must be two finite numbers, low <= high, got "
                                     f"{value!r}")
                object.__setattr__(self, name, (lo, hi))
        if not isinstance(self.fit_info, FitInfo):  # a model file's "fit" section, a dict
            object.__setattr__(self, "fit_info", FitInfo(self.fit_info))
        if self.band is not None and (self.training_range is None
                                      or self.position_range is None):
            raise ValueError("a band needs the training_range and position_range it was "
                             "calibrated with")

    # -- the data path ---------------------------------------------------------------------

    def sensor_offset(self, sensor: np.ndarray) -> np.ndarray | float:
        """Offset removed from a recording's sensor signal (per sample for tare / track)."""
        if self.center == "none":
            return 0.0
        if self.center == ORACLE_CENTER:
            return float(np.mean(sensor))
        level = sensor_level(self.center, sensor, self.structure.dt,
                             tare_seconds=self.tare_seconds, track_seconds=self.track_seconds)
        if level is None:  # fit
            return self.scaling.sensor_offset
        return self.scaling.sensor_offset + level - self.sensor_reference

    def normalised_sensor(self, sensor: np.ndarray) -> np.ndarray:
        """The model's sensor input: offset removed, flipped by ``polarity``, scaled."""
        s = np.asarray(sensor, dtype=float)
        return self.polarity * (s - self.sensor_offset(s)) / self.scaling.sensor_scale

    def position_offset(self, position_mean: float | None = None,
                        rest_position: float | None = None) -> float:
        """Offset [mm] added to the normalised estimate.

        ``position_mean`` is used only by the oracle centring (the recording's true mean);
        ``rest_position`` only by ``tare`` (where the device rests during the tare window, if
        not where it rested in training).
        """
        if self.center == "none":
            return 0.0
        if self.center == ORACLE_CENTER and position_mean is not None:
            return position_mean
        offset = self.scaling.position_offset
        if self.center == "tare" and rest_position is not None and self.rest_position is not None:
            offset += rest_position - self.rest_position
        return offset

    def check_sampling(self, recording: Recording) -> None:
        """The model's Euler step is tied to ``dt``: refuse recordings sampled otherwise."""
        if abs(recording.dt - self.structure.dt) > 0.01 * self.structure.dt:
            raise InputError(
                f"{recording.source}: column 'time': sampled every {recording.dt:.6g} s, but the "
                f"model was fitted at {self.structure.dt:.6g} s; resample the recording first")

    def estimate(self, recording: Recording | np.ndarray, position_mean: float | None = None,
                 *, rest_position: float | None = None) -> np.ndarray:
        """Position estimate [mm] from the recording's sensor signal.

        With every centring but ``recording`` (oracle) the estimate at sample k uses sensor
        samples <= k and the model file only; ``position_mean`` is ignored then. A plain array
        is taken as the sensor samples, one every ``structure.dt``.

        Raises
        ------
        TypeError
            If `recording` is neither a Recording nor a 1-D array of numbers.
        FitDivergedError
            If the model's run diverges, or its output is not finite or beyond
            ``MAX_NORMALISED`` times the training positions (none of it is ever returned);
            the message names the recording, the first such sample and the model file.
        """
        recording = self._as_recording(recording)
        self.check_sampling(recording)
        s = self.normalised_sensor(recording.sensor)
        run = self.family.simulate if self.mode == "direct" else self.family.invert
        with np.errstate(over="ignore", invalid="ignore"):
            try:
                p, _ = run(self.structure, self.params, s)
            except FitDivergedError as exc:  # the family's own guard: say which file and model
                raise FitDivergedError(f"{recording.source}: the {self.model} compensator"
                                       f"{self._from()}: {exc}") from None
            offset = self.position_offset(position_mean, rest_position)
            estimate = p * self.scaling.position_scale + offset
        bad = runaway_samples(p, estimate, self.runaway_bounds(offset))
        if bad.size:
            raise FitDivergedError(
                f"{recording.source}: column 'sensor', sample {bad[0]}: the {self.model} "
                f"compensator{self._from()} gives an estimate that is "
                f"{runaway_kind(estimate[bad[0]])} ({bad.size} such samples)")
        return estimate

    def estimate_with_band(self, recording: Recording | np.ndarray,
                           level: float | None = None, *,
                           rest_position: float | None = None) -> BandedEstimate:
        """Position estimate [mm] with its prediction band (:mod:`hystkit.compensation._band`).

        Causal like :meth:`estimate`: sample k's band uses sensor samples <= k and the model
        file only.

        Parameters
        ----------
        recording : Recording or numpy.ndarray
            As for :meth:`estimate`.
        level : float, optional
            Nominal coverage in (0, 1); default the band's own (0.90 unless fitted otherwise).
        rest_position : float, optional
            As for :meth:`estimate` (``tare``).

        Returns
        -------
        BandedEstimate
            ``estimate``, ``lower`` and ``upper`` [mm].

        Raises
        ------
        InputError
            If the compensator has no band.
        """
        recording = self._as_recording(recording)
        estimate = self.estimate(recording, rest_position=rest_position)
        lower, upper = interval(self, recording, estimate, level)
        return BandedEstimate(estimate, lower, upper)

    def runaway_bounds(self, offset: float) -> tuple[float, float] | None:
        """Estimates [mm] beyond these are refused as a runaway (:func:`runaway_samples`):
        the training positions widened by ``MAX_NORMALISED`` times their extent, shifted
        with the position offset in use; None if the model file does not know them.

        Parameters
        ----------
        offset : float
            The position offset [mm] added to the normalised estimate
            (:meth:`position_offset`).

        Returns
        -------
        tuple of float or None
            ``(low, high)`` [mm].
        """
        if self.position_range is None:
            return None
        lo, hi = self.position_range
        # a normalised estimate of MAX_NORMALISED at the stored scale, if the scale fits these
        # positions (a fit writes their max |position - offset|, at most this extent)
        pad = MAX_NORMALISED * max(hi - lo, abs(lo), abs(hi))
        shift = offset - self.scaling.position_offset
        return (lo + shift - pad, hi + shift + pad) if pad > 0 else None

    def _as_recording(self, data: Recording | np.ndarray) -> Recording:
        """A Recording as it is; a 1-D array of sensor samples at the model's ``dt``."""
        if isinstance(data, Recording):
            return data
        try:
            sensor = np.asarray(data, dtype=float)
        except (TypeError, ValueError):
            sensor = None
        if sensor is None or sensor.ndim != 1:
            raise TypeError(f"estimate takes a Recording (hystkit.read(path)) or a 1-D array of "
                            f"sensor samples taken every {self.structure.dt:g} s, not "
                            f"{type(data).__name__}")
        return Recording(time=np.arange(sensor.size) * self.structure.dt, sensor=sensor,
                         source="<array>")

    def _from(self) -> str:
        return "" if self.source is None else f" of {self.source}"

    def estimate_linear(self, recording: Recording, position_mean: float | None = None, *,
                        rest_position: float | None = None) -> np.ndarray:
        """Position [mm] from the stored straight-line baseline, same conventions."""
        s = self.normalised_sensor(recording.sensor)
        return (self.baseline(s) * self.scaling.position_scale
                + self.position_offset(position_mean, rest_position))

    def oracle(self) -> Compensator:
        """The same model under the paper's protocol (``recording`` centring): an oracle."""
        return replace(self, center=ORACLE_CENTER)

    # -- use-time guards ------------------------------------------------------------------

    def sensor_outside(self, recording: Recording,
                       margin: float = SENSOR_MARGIN) -> np.ndarray | None:
        """Mask of samples whose normalised sensor lies outside the training range.

        The range is widened by ``margin`` of its width on each side; None if the compensator
        does not know it (files from before it was stored).
        """
        if self.training_range is None:
            return None
        lo, hi = self.training_range
        pad = margin * (hi - lo)
        s = self.normalised_sensor(recording.sensor)
        return (s < lo - pad) | (s > hi + pad)

    def estimate_outside(self, estimate: np.ndarray,
                         margin: float = POSITION_MARGIN) -> np.ndarray | None:
        """Mask of estimates [mm] beyond the training position range widened by ``margin``."""
        if self.position_range is None:
            return None
        lo, hi = self.position_range
        pad = margin * (hi - lo)
        offset = self.position_offset() - self.scaling.position_offset
        return (estimate < lo + offset - pad) | (estimate > hi + offset + pad)

    def extrapolated_fraction(self, recording: Recording,
                              margin: float = SENSOR_MARGIN) -> float | None:
        """Share of samples whose sensor value lies outside the range seen in training."""
        mask = self.sensor_outside(recording, margin)
        return None if mask is None else float(np.mean(mask))
