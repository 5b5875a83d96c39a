"""A scikit-learn estimator over :func:`fit_compensator`, for every registered model family.

scikit-learn is not needed to use it (it is imported only when scikit-learn itself asks for
the estimator's tags), but it follows scikit-learn's contract, so ``clone``, ``GridSearchCV``,
``cross_val_score`` and pipelines work. The data are a time series: ``X`` is the sensor signal,
one row per sample *in time order*, so only splitters that keep the order
(``TimeSeriesSplit``) make sense, and shuffling ``X`` changes the answer.
"""

from __future__ import annotations

import inspect
from typing import Any

import numpy as np

from ..io import Recording
from ..metrics import r2
from ._band import DEFAULT_LEVEL, interval
from ._calibration import with_band
from ._centring import DEFAULT_CENTER, ORACLE_CENTER
from ._compensator import Compensator
from ._fitting import fit_compensator

__all__ = ["CompensatorEstimator", "NotFittedError"]


class NotFittedError(ValueError, AttributeError):
    """predict or score before fit (both bases, as scikit-learn's own NotFittedError)."""


class CompensatorEstimator:
    """A compensator (sensor -> position) of any model family, as a scikit-learn regressor.

    ``__init__`` only stores its arguments; ``fit`` returns ``self`` and sets the fitted
    attributes (ending in ``_``).

    Parameters
    ----------
    model : str
        A family of ``hystkit.models.FAMILIES`` (``mpl``, ``pi``, ``preisach``, ...).
    size : int, optional
        The family's size knob (mpl: cells); None: the family's ``default_size``.
    mode : {"direct", "inverse"}
        ``direct`` fits sensor -> position; ``inverse`` fits position -> sensor and inverts it.
    center : {"fit", "tare", "track", "recording", "none"}
        Sensor centring (``docs/centring.md``). ``recording`` is the paper's oracle: it needs
        the true positions' mean, which :meth:`predict` does not have (it then uses the
        training mean); :meth:`score` is deployable for every other centring.
    dt : float, optional
        Sample time [s] of the rows of ``X``. ``X`` holds no time, so it is required unless
        ``fit`` is given ``time``; it must match the rate the model is used at.
    options : dict, optional
        Further keyword arguments of `fit_compensator` (``tare_seconds``, ``track_seconds``,
        ``diagnose``, the family's structure options such as ``slope_cap``).
    band : bool, default True
        Calibrate a prediction band at fit time (:func:`~hystkit.compensation.with_band`: the
        model refitted on interleaved cycles of the data; about four times the fit's time).
    level : float, default 0.90
        The band's nominal coverage.

    Attributes
    ----------
    compensator_ : Compensator
        The fitted compensator (``hystkit.save(est.compensator_, "model.json")`` writes it).
    dt_ : float
        The sample time used [s].
    n_features_in_ : int
        Always 1 (the sensor).

    Examples
    --------
    >>> from sklearn.model_selection import GridSearchCV, TimeSeriesSplit
    >>> from hystkit.compensation import CompensatorEstimator
    >>> from hystkit.sensors import simulate_experiment
    >>> rec = simulate_experiment("noise", seed=1)
    >>> X, y = rec.sensor.reshape(-1, 1), rec.position
    >>> est = CompensatorEstimator("mpl", size=1, dt=rec.dt).fit(X, y)
    >>> est.score(X, y) > 0.9
    True
    >>> search = GridSearchCV(CompensatorEstimator("mpl", dt=rec.dt), {"size": [1, 2]},
    ...                       cv=TimeSeriesSplit(n_splits=2)).fit(X, y)
    >>> search.best_params_["size"] in (1, 2)
    True
    >>> estimate, lower, upper = est.predict(X, return_band=True)
    >>> bool(((lower <= estimate) & (estimate <= upper)).all())
    True
    """

    def __init__(self, model: str = "mpl", size: int | None = None, mode: str = "direct",
                 center: str = DEFAULT_CENTER, dt: float | None = None,
                 options: dict | None = None, band: bool = True,
                 level: float = DEFAULT_LEVEL) -> None:
        self.model = model
        self.size = size
        self.mode = mode
        self.center = center
        self.dt = dt
        self.options = options
        self.band = band
        self.level = level

    # -- scikit-learn's parameter protocol (what BaseEstimator would give) -----------------

    @classmethod
    def _param_names(cls) -> list[str]:
        return [name for name in inspect.signature(cls.__init__).parameters if name != "self"]

    def get_params(self, deep: bool = True) -> dict[str, Any]:
        """The constructor arguments, by name (``deep`` is accepted; there are no nested
        estimators)."""
        return {name: getattr(self, name) for name in self._param_names()}

    def set_params(self, **params: Any) -> CompensatorEstimator:
        """Set constructor arguments by name; returns ``self``.

        Raises
        ------
        ValueError
            A name that is not a constructor argument.
        """
        valid = self._param_names()
        for name, value in params.items():
            if name not in valid:
                raise ValueError(f"invalid parameter {name!r} for CompensatorEstimator; "
                                 f"valid: {', '.join(valid)}")
            setattr(self, name, value)
        return self

    def __repr__(self) -> str:
        changed = [f"{name}={value!r}" for name, value in self.get_params().items()
                   if value != inspect.signature(type(self).__init__).parameters[name].default]
        return f"CompensatorEstimator({', '.join(changed)})"

    def __sklearn_tags__(self):
        """scikit-learn's tags: a regressor, one feature, no NaN, order matters."""
        # scikit-learn is optional: only its own checks ask for the tags
        from sklearn.utils import InputTags, RegressorTags, Tags, TargetTags

        return Tags(estimator_type="regressor", target_tags=TargetTags(required=True),
                    regressor_tags=RegressorTags(), input_tags=InputTags(allow_nan=False))

    # -- fit / predict / score ------------------------------------------------------------

    def fit(self, X: Any, y: Any, time: Any = None) -> CompensatorEstimator:
        """Fit on the sensor signal ``X`` (n, 1) and the position ``y`` (n,) [mm].

        Parameters
        ----------
        X : array_like, shape (n, 1)
            Sensor samples in time order.
        y : array_like, shape (n,)
            Reference position [mm] at the same samples.
        time : array_like, shape (n,), optional
            Sample times [s]; when given, ``dt`` is taken from them (and must agree with the
            ``dt`` parameter if that is set too).

        Returns
        -------
        self
        """
        if y is None:
            raise ValueError("requires y to be passed, but the target y is None")
        sensor = _sensor_column(X)
        position = _target(y, sensor.size)
        if time is not None:
            recording = Recording(time=time, sensor=sensor, position=position,
                                  source="<CompensatorEstimator.fit>")
            if self.dt is not None and not np.isclose(recording.dt, self.dt, rtol=1e-6):
                raise ValueError(f"time is sampled every {recording.dt:g} s but dt is "
                                 f"{self.dt:g} s")
        else:
            recording = Recording(time=np.arange(sensor.size) * self._dt(), sensor=sensor,
                                  position=position, source="<CompensatorEstimator.fit>")
        options = dict(self.options or {})
        comp = fit_compensator(recording, self.size, model=self.model, mode=self.mode,
                               center=self.center, **options)
        if self.band:
            options.pop("diagnose", None)
            size = comp.family.default_size if self.size is None else self.size
            comp = with_band(comp, [recording], size, options, level=self.level)
        self.compensator_: Compensator = comp
        self.dt_ = recording.dt
        self.n_features_in_ = 1
        self.training_position_mean_ = float(np.mean(position))
        return self

    def _dt(self) -> float:
        if self.dt is None:
            raise ValueError("CompensatorEstimator needs dt, the sample time [s] of the rows "
                             "of X (or fit(X, y, time=...))")
        if not float(self.dt) > 0:
            raise ValueError(f"dt must be a positive sample time [s], got {self.dt!r}")
        return float(self.dt)

    def _fitted(self) -> Compensator:
        if not hasattr(self, "compensator_"):
            raise NotFittedError("this CompensatorEstimator is not fitted yet; call fit first")
        return self.compensator_

    def predict(self, X: Any, return_band: bool = False
                ) -> np.ndarray | tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position estimate [mm] for the sensor signal ``X`` (n, 1), from the model's rest
        state at the first sample (see `Compensator.estimate`).

        Parameters
        ----------
        X : array_like, shape (n, 1)
            Sensor samples in time order.
        return_band : bool, default False
            Also return the prediction band at the estimator's ``level``.

        Returns
        -------
        estimate : numpy.ndarray
            The position estimate [mm]; with `return_band`, ``(estimate, lower, upper)``.
        """
        comp = self._fitted()
        sensor = _sensor_column(X)
        recording = Recording(time=np.arange(sensor.size) * self.dt_, sensor=sensor,
                              source="<CompensatorEstimator.predict>")
        mean = self.training_position_mean_ if comp.center == ORACLE_CENTER else None
        estimate = comp.estimate(recording, position_mean=mean)
        if not return_band:
            return estimate
        return (estimate, *interval(comp, recording, estimate, self.level))

    def score(self, X: Any, y: Any, sample_weight: Any = None) -> float:
        """Deployable R² of :meth:`predict` against the position ``y`` (the estimate uses no
        knowledge of ``y``; with ``center="recording"`` it uses the training mean)."""
        if sample_weight is not None:
            raise ValueError("sample_weight is not supported: every sample of a time series "
                             "counts once")
        y = _target(y, _sensor_column(X).size)
        return r2(y, self.predict(X))


def _sensor_column(X: Any) -> np.ndarray:
    """``X`` as a float64 vector: one column (the sensor), at least 2 finite real rows."""
    if hasattr(X, "tocsr"):  # scipy.sparse, without importing scipy
        raise TypeError("sparse input is not supported: pass the sensor signal as a dense "
                        "array of shape (n_samples, 1)")
    values = np.asarray(X)
    if values.ndim != 2:
        raise ValueError(f"Expected 2D array of shape (n_samples, 1), got {values.ndim}D; "
                         f"reshape a sensor vector with X.reshape(-1, 1)")
    if values.shape[1] == 0:
        raise ValueError(f"Found array with 0 feature(s) (shape={values.shape}) while a minimum "
                         f"of 1 is required.")
    if values.shape[1] != 1:
        raise ValueError(f"X has {values.shape[1]} features, but CompensatorEstimator is "
                         f"expecting 1 feature (the sensor signal) as input")
    if np.iscomplexobj(values):
        raise ValueError("Complex data not supported")
    return np.asarray(values[:, 0], dtype=np.float64)


def _target(y: Any, n: int) -> np.ndarray:
    values = np.asarray(y)
    if np.iscomplexobj(values):
        raise ValueError("Complex data not supported")
    if values.ndim == 2 and values.shape[1] == 1:
        values = values[:, 0]
    values = np.asarray(values, dtype=np.float64)
    if values.ndim != 1 or values.size != n:
        raise ValueError(f"y must be one position per row of X ({n}), got shape "
                         f"{np.shape(y)}")
    return values
