"""The family protocol: what every hysteresis model family provides, in one place.

A *family* (mPL, Preisach, PI, ...) is one folder ``hystkit/models/<family>/``: its
``__init__`` declares ``INFO``, a :class:`FamilyInfo` (what the CLI lists before any model
loads), and its ``family.py`` exports ``FAMILY``, an instance of a :class:`Family` subclass
whose ``info`` is that record. Generic code (fit,
compensator, compare, control loop, stability, python-control adapter) talks to families only
through this protocol, so adding a family is one new folder and no edit elsewhere.

Conventions, shared by every family:

- **Explicit state.** A model's memory is a float64 vector ``x`` passed in and returned; nothing
  is kept in objects. ``step`` gives the output from the *present* state and then the next
  state, so ``simulate`` over a split run continued from ``x_end`` equals the whole run.
- **Structure and parameters.** ``Structure`` holds what is not fitted (sizes, sample time
  ``dt``, integration limits); ``Params`` holds the fitted quantities. Both are frozen
  dataclasses deriving from :class:`Record`, which gives JSON round trips and equality once.
- **Normalised units.** Fits and the compensator work on data centred and scaled to max |.| = 1
  (eq. 5.10); a family's documented parameter domain is stated for those units.
- **Inverse.** ``invert`` / ``invert_step`` are ``None`` for a family without an inverse, and
  ``no_inverse_reason`` says why.
- **Compiled block.** :meth:`Family.block` returns a numba function with the signature
  ``step(body, x, xn, off, u) -> out`` and the flat float64 ``body`` it reads: the output from
  ``x[off:off + n_state]``, the next state written to ``xn[off:off + n_state]``. The closed
  loop calls these for every slot, so any family runs compiled in any slot.
- **Export.** :attr:`Family.export` is the block written as C99 and MATLAB (a
  :class:`Translation`, from the family's ``export.py``); ``None`` makes ``hystkit export``
  refuse the family with ``no_export_reason`` (:meth:`Family.export_refusal`).
"""

from __future__ import annotations

import dataclasses
import importlib
from abc import ABC, abstractmethod
from collections.abc import Callable
from types import ModuleType
from typing import Any, ClassVar

import numpy as np

from ._capabilities import Capabilities
from ._linearise import numerical_linearisation
from ._method_results import (
    Block,
    FitStart,
    Reduction,
)
from ._record import (
    Record,
    _count_numbers,
)
from ._translation import Translation

__all__ = ["Block", "Capabilities", "Family", "FamilyInfo", "FitStart", "Record", "Reduction",
           "Translation", "numerical_linearisation"]


@dataclasses.dataclass(frozen=True)
class FamilyInfo:
    """What the registry knows of a family before its code loads (``hystkit fit --help``).

    A family folder's ``__init__`` declares it as ``INFO``; its :class:`Family` subclass sets
    ``info = INFO`` and so carries the same values (``Family.name``, ...). The fields are
    those of :class:`Family` of the same names.

    Parameters
    ----------
    name : str
        CLI name (``hystkit fit --model NAME``).
    title : str
        Human name with the reference document's section.
    size_help : str, default "model size"
        What the size knob means.
    default_size : int, default 1
    max_size : int, default 50
        Largest size a fit is offered.
    docs : str, default ""
        Path of the family's page under ``docs/``.
    no_inverse_reason : str, default ""
        Empty when the family has an inverse; otherwise why not.
    """

    name: str
    title: str
    size_help: str = "model size"
    default_size: int = 1
    max_size: int = 50
    docs: str = ""
    no_inverse_reason: str = ""

    @property
    def has_inverse(self) -> bool:
        return not self.no_inverse_reason

    @classmethod
    def of(cls, family: Family) -> FamilyInfo:
        """The record of a family object (one registered at run time or by a plugin)."""
        return cls(**{f.name: getattr(family, f.name) for f in dataclasses.fields(cls)})


class Family(ABC):
    """One hysteresis model family. Subclass it once per family; export an instance as FAMILY.

    Attributes
    ----------
    info : FamilyInfo or None
        The folder's ``INFO``; when set, the metadata below (``name`` to ``max_size``,
        ``docs``, ``no_inverse_reason``) are taken from it.
    name : str
        CLI name (``hystkit fit --model NAME``).
    title : str
        Human name with the reference document's section.
    size_help : str
        What the size knob means (cells, operators, grid levels ...).
    default_size : int
    max_size : int
        Largest size a fit is offered (the CLI refuses more, before any work): beyond it a fit
        takes hours or its Jacobian stops being solvable. The structure's own validation may
        allow more (a hard memory limit for model files).
    docs : str
        Path of the family's page under ``docs/``.
    Structure, Params : type
        The family's frozen dataclasses (both derive from :class:`Record`).
    no_inverse_reason : str
        Empty when the family has an inverse; otherwise why not (``invert`` is then None).
    export : Translation or None
        The block in C and MATLAB (the family's ``export.py``); None: not exportable.
    no_export_reason : str
        Why there is no ``export`` (``hystkit export`` says it); a default names the file.
    capabilities : Capabilities
        What the family can do beyond the abstract members (losses, the sum |w| constraint,
        linear output, synchronisation amplitude, given starts, inverse); generic code reads
        only this record. The default declares nothing: the plain SSE only.
    """

    info: ClassVar[FamilyInfo | None] = None
    name: ClassVar[str]
    title: ClassVar[str]
    size_help: ClassVar[str] = "model size"
    default_size: ClassVar[int] = 1
    max_size: ClassVar[int] = 50
    docs: ClassVar[str] = ""
    Structure: ClassVar[type]
    Params: ClassVar[type]
    no_inverse_reason: ClassVar[str] = ""
    export: ClassVar[Translation | None] = None
    no_export_reason: ClassVar[str] = ""

    model: ClassVar[ModuleType | None] = None
    """The module of the family's pure functions. ``rest_state``, ``step``, ``simulate`` and,
    for a family with an inverse, ``invert`` / ``invert_step`` default to its functions of the
    same names and signatures (``rest_state(structure, params, value, inverse)``)."""

    # None when the family has no inverse; otherwise methods
    #   invert(structure, params, y, x0=None) -> (u_hat, x_end)
    #   invert_step(structure, params, x, y) -> (u_hat, x_next)
    # taken from ``model`` unless the family defines them.
    invert: ClassVar[Callable[..., tuple[np.ndarray, np.ndarray]] | None] = None
    invert_step: ClassVar[Callable[..., tuple[float, np.ndarray]] | None] = None

    capabilities: ClassVar[Capabilities] = Capabilities()

    fit_options: ClassVar[frozenset[str]] = frozenset()
    """Optional keywords of the family's fit beyond the common ones (``init`` from
    :meth:`start_options`, ``weight_sum_max`` for the document's constraint sum |w| <= B), so
    that a caller can refuse an option the family lacks before any work; those of
    :attr:`capabilities` (``Capabilities.fit_options``)."""

    fit_function: ClassVar[Callable[..., Any] | str | None] = None
    """The family's fit function, ``fit_x(u, y, structure, *, accept, accept_reason,
    **options) -> FitResult``; the default :meth:`fit` calls it. A string ``"module.name"``
    names it inside the family's package, imported on the first fit: a fit module loads the
    optimisers (scipy.optimize and the identification package, +0.6-0.95 s measured per
    family), which running a model does not need."""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        info = cls.__dict__.get("info")
        if info is not None:  # the metadata are declared once, in the folder's INFO
            for field in dataclasses.fields(info):
                setattr(cls, field.name, getattr(info, field.name))
        # the inverse is declared once, by no_inverse_reason; fit_options follow the record
        cls.capabilities = dataclasses.replace(cls.capabilities,
                                               inverse=not cls.no_inverse_reason)
        cls.fit_options = cls.capabilities.fit_options
        fit_function = cls.__dict__.get("fit_function")
        if callable(fit_function) and not isinstance(fit_function, staticmethod):
            cls.fit_function = staticmethod(fit_function)  # a plain function, not a method
        module = cls.__dict__.get("model")
        if module is None or cls.no_inverse_reason:
            return
        if "invert" not in cls.__dict__ and hasattr(module, "invert"):
            cls.invert = lambda self, structure, params, y, x0=None: module.invert(
                structure, params, y, x0)
        if "invert_step" not in cls.__dict__ and hasattr(module, "invert_step"):
            cls.invert_step = lambda self, structure, params, x, y: module.invert_step(
                structure, params, x, y)

    # Older names, kept so that code written against the first registry keeps working.
    @property
    def structure_type(self) -> type:
        return self.Structure

    @property
    def params_type(self) -> type:
        return self.Params

    @property
    def has_inverse(self) -> bool:
        return self.invert is not None

    def __repr__(self) -> str:
        return f"<hystkit model family {self.name!r}>"

    def export_refusal(self, inverse: bool = False) -> str:
        """Why the family (its inverse when `inverse`) cannot be exported; empty when it can."""
        if self.export is None:
            return self.no_export_reason or (
                f"no translation of family {self.name!r} (a family's C and MATLAB code is its "
                f"export.py, see docs/models/README.md)")
        if inverse and not self.export.inverse:
            return f"the {self.name} family has no inverse to translate"
        return ""

    # -- structure --------------------------------------------------------------------------

    @abstractmethod
    def make_structure(self, dt: float, size: int, **options: Any) -> Any:
        """``(dt [s], size, **options) -> Structure``; ``size`` is the family's size knob."""

    def at(self, structure: Any, dt: float) -> Any:
        """The same model at sample time ``dt`` (the loop's ``Ts``).

        The default replaces ``dt``, right for a model that is a discretised ODE whose
        parameters do not depend on the step. A family for which that is wrong overrides this
        or raises ``ValueError`` saying why.
        """
        return dataclasses.replace(structure, dt=float(dt))

    def random_params(self, structure: Any, rng: np.random.Generator) -> Any:
        """Parameters drawn at random from the family's *documented domain*: the ranges its
        docs promise behave (bounded output for inputs within [-1, 1]); the contract test
        draws from it. The docstring of an override states the domain."""
        raise NotImplementedError(f"family {self.name!r} documents no parameter domain")

    def presets(self) -> dict[str, tuple[Any, Any, dict]]:
        """Named published parameter sets: ``name -> (structure, params, info)``; ``info`` says
        where the values come from. Default: none."""
        return {}

    def start_options(self, structure: Any, params: Any) -> FitStart:
        """Fit options that start the family's fit from exactly ``params`` (``--init``).

        Parameters
        ----------
        structure : Structure
            The structure the fit will use (the cell count must match ``params``).
        params : Params
            The start, in normalised units (eq. 5.10).

        Returns
        -------
        FitStart
            ``options`` to pass to :meth:`fit` and the notes on coordinates moved into the
            fit's box.

        Raises
        ------
        NotImplementedError
            For a family whose fit cannot start from given parameters (the default).
        """
        raise NotImplementedError(f"the {self.name} fit cannot start from given parameters "
                                  f"(--init); it has its own starts")

    def n_params(self, structure: Any, params: Any) -> int:
        """Number of fitted numbers (for information criteria): every number in
        ``params.to_dict()``, nested lists included. Override when some are fixed."""
        return _count_numbers(params.to_dict())

    def fixed_params(self, structure: Any, params: Any) -> tuple[str, ...]:
        """Stored parameters the family's fit holds fixed (a gauge it does not fit), by name.

        Names follow the float entries of ``params.to_dict()``, depth first: ``"v_b"``,
        ``"w[0]"``, ``"a[0][2]"``. The fit's standard errors leave these out (they are
        reported as fixed by the fit, not as undetermined by the data) and so does its count
        of fitted numbers for AIC / BIC. Default: none.
        """
        return ()

    def reductions(self, structure: Any, params: Any) -> tuple[Reduction, ...]:
        """Models one size smaller made from ``params`` without refitting (a cell dropped, two
        cells merged), for the fit's check of redundant cells
        (:func:`hystkit.compensation.redundancy_notes`): when one of them describes the
        training data as well, the data do not identify the larger model. Default: none."""
        return ()

    # -- running ----------------------------------------------------------------------------

    def rest_state(self, structure: Any, params: Any, value: float,
                   inverse: bool = False) -> np.ndarray:
        """State at rest under a constant input ``value`` (forward) or output (``inverse``)."""
        return self._module("rest_state").rest_state(structure, params, value, inverse)

    def step(self, structure: Any, params: Any, x: np.ndarray,
             u: float) -> tuple[float, np.ndarray]:
        """One sample: output from the present state, then the next state (readable)."""
        return self._module("step").step(structure, params, x, u)

    def simulate(self, structure: Any, params: Any, u: np.ndarray,
                 x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Run over ``u`` (compiled); ``x0=None`` starts at rest at ``u[0]``."""
        return self._module("simulate").simulate(structure, params, u, x0)

    def _module(self, what: str) -> ModuleType:
        if self.model is None:
            raise NotImplementedError(f"family {self.name!r} defines no {what} and no model "
                                      f"module to take it from")
        return self.model

    # -- identification ---------------------------------------------------------------------

    def fit(self, u: np.ndarray, y: np.ndarray, structure: Any, *,
            accept: Callable[[Any], bool] | None = None,
            accept_reason: str = "rejected by the acceptance test", **options: Any) -> Any:
        """Fit ``u -> y`` (centred, normalised data) and return a ``FitResult``.

        The default calls :attr:`fit_function`; a family without one overrides this."""
        function = self.fit_function
        if function is None:
            raise NotImplementedError(f"family {self.name!r} defines no fit and no "
                                      f"fit_function")
        if isinstance(function, str):  # "fit.fit_pl": the optimisers load on the first fit
            module, _, name = function.rpartition(".")
            package = type(self).__module__.rpartition(".")[0]
            function = getattr(importlib.import_module(f"{package}.{module}"), name)
        return function(u, y, structure, accept=accept, accept_reason=accept_reason, **options)

    # -- loop -------------------------------------------------------------------------------

    @abstractmethod
    def block(self, structure: Any, params: Any, inverse: bool = False) -> Block:
        """The model (or its inverse) compiled for the closed loop, at ``structure.dt``."""

    def linearise(self, structure: Any, params: Any, x: np.ndarray, u: float,
                  inverse: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Discrete linearisation ``(A, B, C, D)`` of one step at state ``x`` and input ``u``.

        The default differentiates :meth:`step` (or ``invert_step``) numerically; families
        with an analytical form override it and test that the two agree.
        """
        run = self.invert_step if inverse else self.step
        if run is None:
            raise ValueError(f"model {self.name!r} has no inverse ({self.no_inverse_reason})")
        return numerical_linearisation(lambda xx, uu: run(structure, params, xx, uu), x, u)


    def stability_details(self, structure: Any, params: Any, u: np.ndarray) -> dict | None:
        """Family-specific stability facts beyond the generic eigenvalue scan of
        :func:`hystkit.models.stability_report` (the mPL families: eq. 5.28 per cell, knees,
        rest points); None when the family has none."""
        return None
