"""A fitted compensator: sensor signal in, position estimate out (sec. 5.3.4-5.3.6).

Two ways to get one, for any registered model family (``hystkit.models.FAMILIES``;
the mPL by default):

- ``direct`` (paper 9.2): fit the model from sensor to position; the model *is* the
  compensator.
- ``inverse`` (paper 9.1): fit the forward model position -> sensor and run its inverse
  (for the mPL the analytical eq. 5.13-5.14) on sensor data; only for families with an inverse.

Data pass through the same path at fit and at use: centring (``center``), scaling by the fitting
recording's max |.| (eq. 5.10), the model, and back to mm. Centring choices:

- ``recording`` (paper 9.2, default): each recording's own mean is removed from its sensor
  signal and, for evaluation, its position; this hides offset drift between recordings.
- ``fit``: the fitting recording's means are removed from every recording (honest about drift).
- ``none``: no offsets at all.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import FitDivergedError, InputError
from ..identification import FitResult
from ..io import Recording
from ..models import Family, get_family

__all__ = ["CENTERS", "MODES", "Compensator", "LinearBaseline", "Scaling", "fit_compensator"]

MODES = ("direct", "inverse")
CENTERS = ("recording", "fit", "none")


@dataclass(frozen=True)
class Scaling:
    """Offsets and scales of the fitting recording (eq. 5.10), sensor units and mm."""

    sensor_offset: float
    sensor_scale: float
    position_offset: float
    position_scale: float


@dataclass(frozen=True)
class LinearBaseline:
    """Least-squares straight line position(sensor) in normalised units (MATLAB polyfit)."""

    slope: float
    intercept: float

    def __call__(self, s: np.ndarray) -> np.ndarray:
        return self.slope * s + self.intercept


@dataclass(frozen=True, eq=False)
class Compensator:
    """Fitted compensator with its data conventions; apply it with :meth:`estimate`.

    ``model`` names the family in the registry; ``structure`` and ``params`` are that family's
    dataclasses.
    """

    structure: Any
    params: Any
    mode: str
    center: str
    scaling: Scaling
    baseline: LinearBaseline
    fit_info: dict = field(default_factory=dict)
    model: str = "mpl"
    training_range: tuple[float, float] | None = None

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
        if self.training_range is not None:
            lo, hi = (float(v) for v in self.training_range)
            if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
                raise ValueError(f"training_range must be two finite numbers, low <= high, got "
                                 f"{self.training_range!r}")
            object.__setattr__(self, "training_range", (lo, hi))

    def _normalised_sensor(self, sensor: np.ndarray) -> np.ndarray:
        offset = {"recording": np.mean(sensor), "fit": self.scaling.sensor_offset,
                  "none": 0.0}[self.center]
        return (np.asarray(sensor, dtype=float) - offset) / self.scaling.sensor_scale

    def _to_mm(self, p: np.ndarray, position_mean: float | None) -> np.ndarray:
        if self.center == "none":
            offset = 0.0
        elif self.center == "recording" and position_mean is not None:
            offset = position_mean
        else:
            offset = self.scaling.position_offset
        return p * self.scaling.position_scale + offset

    def check_sampling(self, recording: Recording) -> None:
        """The model's Euler step is tied to ``dt``: refuse recordings sampled otherwise."""
        if abs(recording.dt - self.structure.dt) > 0.01 * self.structure.dt:
                raise InputError(
                f"{recording.source}: column 'time': sampled every {recording.dt:.6g} s, but the "
                f"model was fitted at {self.structure.dt:.6g} s; resample the recording first")

    def estimate(self, recording: Recording, position_mean: float | None = None) -> np.ndarray:
        """Position estimate [mm] from the recording's sensor signal.

        Parameters
        ----------
        recording : Recording
            Needs ``time`` and ``sensor``; sampled at the model's ``dt``.
        position_mean : float, optional
            With ``center="recording"`` the estimate is only known up to the recording's mean
            position; pass it (evaluation does) or the fitting recording's mean is used.
        """
        self.check_sampling(recording)
        s = self._normalised_sensor(recording.sensor)
        run = self.family.simulate if self.mode == "direct" else self.family.invert
        p, _ = run(self.structure, self.params, s)
        return self._to_mm(p, position_mean)

    def extrapolated_fraction(self, recording: Recording, margin: float = 0.05) -> float | None:
        """Share of samples whose sensor value lies outside the range seen in training.

        The range (normalised units) is widened by ``margin`` of its width on each side; None if
        the compensator does not know its training range (files from before it was stored).
        Beyond that range every model extrapolates, and the generalisation matrix shows how
        badly that can end.
        """
        if self.training_range is None:
            return None
        lo, hi = self.training_range
        pad = margin * (hi - lo)
        s = self._normalised_sensor(recording.sensor)
        return float(np.mean((s < lo - pad) | (s > hi + pad)))

    def estimate_linear(self, recording: Recording,
                        position_mean: float | None = None) -> np.ndarray:
        """Position [mm] from the stored straight-line baseline, same conventions."""
        return self._to_mm(self.baseline(self._normalised_sensor(recording.sensor)),
                           position_mean)


def _centre_and_scale(recording: Recording, center: str) -> tuple[Scaling, np.ndarray,
                                                                  np.ndarray]:
    s_off = float(np.mean(recording.sensor)) if center != "none" else 0.0
    p_off = float(np.mean(recording.position)) if center != "none" else 0.0
    s = recording.sensor - s_off
    p = recording.position - p_off
    scaling = Scaling(s_off, float(np.max(np.abs(s))), p_off, float(np.max(np.abs(p))))
    if scaling.sensor_scale == 0 or scaling.position_scale == 0:
        column = "sensor" if scaling.sensor_scale == 0 else "position"
        raise InputError(f"{recording.source}: column '{column}' is constant; nothing to fit")
    return scaling, s / scaling.sensor_scale, p / scaling.position_scale


def _inverse_is_bounded(family: Family, structure: Any, params: Any,
                        s: np.ndarray) -> bool:
    try:
        p_hat, _ = family.invert(structure, params, s)
    except FitDivergedError:
        return False
    return bool(np.max(np.abs(p_hat)) < 10.0)  # normalised data: |p| <= 1 when it works


def fit_compensator(recording: Recording, size: int | None = None, *, model: str = "mpl",
                    mode: str = "direct", center: str = "recording",
                    **structure_options: Any) -> Compensator:
    """Fit a compensator and its straight-line baseline on one recording.

    Parameters
    ----------
    recording : Recording
        Fitting recording with ``time`` [s], ``position`` [mm] and ``sensor``.
    size : int, optional
        The family's size knob (mPL: cells N, 3N + 2 parameters); default per family.
    model : str
        Registered model family (``hystkit.models.FAMILIES``).
    mode : {"direct", "inverse"}
    center : {"recording", "fit", "none"}
        See the module docstring.
    **structure_options
        Passed to the family's ``make_structure`` (mPL: ``slope_cap``).
    """
    family = get_family(model)
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}, got {mode!r}")
    if center not in CENTERS:
        raise ValueError(f"center must be one of {CENTERS}, got {center!r}")
    if mode == "inverse" and family.invert is None:
        raise InputError(f"model {model!r} has no inverse ({family.no_inverse_reason}); "
                         f"use --mode direct")
    if not recording.has_position():
        raise InputError(f"{recording.source}: column 'position' is needed to fit")
    scaling, s, p = _centre_and_scale(recording, center)
    structure = family.make_structure(recording.dt, family.default_size if size is None
                                      else size, **structure_options)
    if mode == "direct":
        result: FitResult = family.fit(s, p, structure)
    else:
        # The exact inverse of a discrete forward model can be unstable even when the model is
        # not (for the mPL its cells see a self-gain 1 + w_k / w_0); only keep fits whose
        # inverse stays bounded on the training data.
        result = family.fit(p, s, structure, accept=lambda params: _inverse_is_bounded(
            family, structure, params, s), accept_reason="their inverse diverges on the "
                                                         "training data; use --mode direct or "
                                                         "a smaller model")
    slope, intercept = np.polyfit(s, p, 1)
    info = {"cost": result.cost, "fit_seconds": result.seconds,
            "n_evaluations": result.n_evaluations, "converged": result.converged,
            "message": result.message, "n_starts": result.n_starts,
            "training_source": recording.source, "training_samples": recording.n_samples}
    return Compensator(training_range=(float(s.min()), float(s.max())),
                       structure=structure, params=result.params, mode=mode, center=center,
                       scaling=scaling, baseline=LinearBaseline(float(slope), float(intercept)),
                       fit_info=info, model=model)
