"""Identification of the Bouc-Wen oscillator (force in, displacement out).

The fit minimises the sum of squared simulation errors (the cost of eq. 5.9) with
``fit_multistart`` (trust-region reflective, finite-difference Jacobian) in two stages, both from
deterministic starts:

1. Linear oscillator (``beta = gamma = 0``, so ``z = alpha y``): only ``K0 = k + alpha``, ``w0``
   and ``zeta`` matter; starts on a grid of natural frequencies spanning the record length to the
   integration limit and two damping ratios.
2. Full model from the best linear fit, over a grid of hysteretic shares ``r = alpha / K0`` and
   loop shapes (loading and unloading slopes ``(beta +- gamma) y_ref`` of either sign, ``nu = 1``).

Bounds keep ``w0 h <= 1`` (RK4 is stable up to about 2.8); a parameter set whose integration
still diverges (a stiff hysteretic element, a very large damping ratio) gets a large constant
residual instead of NaN, so the solver backs off.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ...errors import FitDivergedError
from ...identification import FitResult, FitTimer, fit_multistart
from . import kernels
from . import model as boucwen

__all__ = ["MIN_SAMPLES", "fit_boucwen", "fit_family", "parameter_bounds"]

_ZETA_BOUNDS = (1e-4, 10.0)
_LOGIT_R_BOUND = 9.0  # r = alpha / K0 in [1.2e-4, 1 - 1.2e-4]
_NU_BOUNDS = (1.0, 4.0)
_SHAPE_BOUND = 1e3  # |beta|, |gamma| <= 1e3 / y_ref: loops far sharper than the record resolves
_PENALTY = 1e3  # residual of a diverged run, in units of max |y|
MIN_SAMPLES = 8  # more samples than the 7 parameters


def _reference_amplitude(y: np.ndarray) -> float:
    return 2.0 * float(np.sqrt(np.mean(y**2)))


def parameter_bounds(structure: boucwen.BoucWenStructure, u: np.ndarray, y: np.ndarray,
                     duration: float, bounded: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Box bounds on :meth:`BoucWenParams.to_vector` for a fit of ``y`` to ``u``.

    ``K0`` within four decades of the static gain ``u / y``, ``w0`` from one cycle per record
    (``duration`` [s]) to ``1 / h`` (the RK4 step ``h = dt / substeps``), the shape parameters
    scaled by the output amplitude ``y_ref = 2 rms(y)``. ``u`` and ``y`` are paired samples.
    ``bounded`` keeps ``beta + gamma`` and ``beta - gamma`` non-negative (bounded ``z``).

    Parameters
    ----------
    structure : boucwen.BoucWenStructure
        The model's structure.
    u, y : numpy.ndarray, shape (n,)
        Paired force and displacement samples.
    duration : float
        Length [s] of the record.
    bounded : bool, default False
        Keep ``beta + gamma`` and ``beta - gamma`` non-negative.

    Returns
    -------
    lower, upper : numpy.ndarray, shape (7,)
        Bounds on the parameter vector (:meth:`BoucWenParams.to_vector`).
    """
    gain = float(np.dot(u, y) / np.dot(u, u))
    k0 = 1.0 / gain if gain > 0 else float(np.std(u) / np.std(y))
    shape = _SHAPE_BOUND / _reference_amplitude(y)
    lower = np.array([np.log(k0) - np.log(1e4), np.log(2 * np.pi / duration),
                      np.log(_ZETA_BOUNDS[0]), -_LOGIT_R_BOUND, 0.0 if bounded else -shape,
                      0.0 if bounded else -shape, _NU_BOUNDS[0]])
    upper = np.array([np.log(k0) + np.log(1e4), np.log(1.0 / structure.step_size),
                      np.log(_ZETA_BOUNDS[1]), _LOGIT_R_BOUND, shape, shape, _NU_BOUNDS[1]])
    return lower, upper


_NAMES = ("log_k0", "log_omega0", "log_zeta", "logit_r", "beta+gamma", "beta-gamma", "nu")


def _theta_limits(bounded: bool) -> tuple[list[str | None], list[str | None]]:
    """Which bounds of :func:`parameter_bounds` are limits of the model or of what a record can
    tell, with a note for each; the others are a search box (a fit there is on bounds).

    * ``logit r = +-9``: ``r = alpha / K0`` within 1.2e-4 of 0 or 1, an all but purely
      hysteretic or purely elastic restoring force; past it the output changes by less.
    * ``beta +- gamma`` at ``+-1e3 / y_ref``: the loop turns within 1e-3 of the output's
      amplitude, sharper than the record resolves; ``bounded``: at 0, the edge of the class
      whose ``z`` stays bounded.
    * ``log omega0`` at ``log(1 / h)``: the resonance at the integrator's step.
    * ``nu = 1``: the classic Bouc-Wen loop, the smallest exponent of the family.
    """
    sharp = "the loop turns sharper than the record resolves ({} at its bound +-1e3 / y_ref)"
    edge = "the edge of the loops whose z stays bounded ({} = 0)"
    lower: list[str | None] = [None, None, None,
                               "r = alpha / K0 at 1.2e-4: an all but purely elastic spring",
                               (edge if bounded else sharp).format("beta + gamma"),
                               (edge if bounded else sharp).format("beta - gamma"),
                               "nu = 1: the classic Bouc-Wen loop"]
    upper: list[str | None] = [None, "the resonance sits at the integration step (omega0 h = 1)",
                               None, "r = alpha / K0 at 1 - 1.2e-4: an all but linear spring",
                               sharp.format("beta + gamma"), sharp.format("beta - gamma"), None]
    return lower, upper


def _linear_starts(lower: np.ndarray, upper: np.ndarray,
                   simulate_linear: Callable[[np.ndarray], np.ndarray | None],
                   y: np.ndarray) -> list[np.ndarray]:
    """Natural frequencies from 10 cycles per record to a quarter of the limit, two dampings.

    The linear output is proportional to ``1 / K0``, so each start ``(log K0, log w0,
    log zeta)`` gets its best ``K0`` by linear least squares on a run with ``K0 = 1``.
    """
    omegas = np.linspace(lower[1] + np.log(10.0), upper[1] - np.log(4.0), 4)
    starts = []
    for log_w0 in omegas:
        for zeta in (0.05, 0.7):
            theta = np.array([0.0, log_w0, np.log(zeta)])
            y_unit = simulate_linear(theta)
            gain = float(y_unit @ y / (y_unit @ y_unit)) if y_unit is not None else 0.0
            if gain > 0:
                theta[0] = -np.log(gain)
                starts.append(theta)
    return starts


def _hysteretic_starts(linear: np.ndarray, y_ref: float, nu: float) -> list[np.ndarray]:
    """The linear fit, and a grid of shares and loop shapes around it.

    ``rho = (beta +- gamma) y_ref^nu`` is about the relative change of the hysteretic
    element's tangent stiffness over the amplitude ``y_ref``: ``alpha (1 - rho_load ...)`` on
    loading, ``alpha (1 + rho_unload ...)`` on unloading (:class:`BoucWenParams`). The grid has
    a classic loop (softening loading, stiff unloading) and one that stiffens on loading as
    well (the benchmark's kind).
    """
    log_k0, log_w0, log_zeta = linear
    starts = [np.array([log_k0, log_w0, log_zeta, 0.0, 0.0, 0.0, nu])]
    for r in (0.3, 0.7):
        for rho_load, rho_unload in ((1.5, 3.0), (-0.5, 3.0)):
            starts.append(np.array([log_k0, log_w0, log_zeta, np.log(r / (1 - r)),
                                    rho_load / y_ref**nu, rho_unload / y_ref**nu, nu]))
    return starts


def fit_boucwen(u: np.ndarray, y: np.ndarray, structure: boucwen.BoucWenStructure, *,
                nu: float | None = None, bounded: bool = False, stride: int = 1,
                discard: int = 0,
                max_nfev: int = 200, screen_nfev: int = 10, n_polish: int = 2,
                accept: Callable[[boucwen.BoucWenParams], bool] | None = None,
                accept_reason: str = "rejected by the acceptance test",
                solver: str = "tr", loss: str = "linear", f_scale: float = 1.0,
                weights: np.ndarray | None = None) -> FitResult:
    """Fit a Bouc-Wen oscillator mapping the force ``u`` to the displacement ``y`` (SSE, eq. 5.9).

    Parameters
    ----------
    u : array, shape (n,)
        Force sampled every ``structure.dt``; the run starts as ``structure.start`` says.
    y : array, shape (len(u[::stride]) - discard,)
        Target displacement: the model output ``y_model[::stride][discard:]`` is compared with
        it. ``stride > 1`` fits a model that runs on a band-limited upsampled force
        (:func:`~hystkit.models.boucwen.bandlimited_upsample`); ``discard`` drops a transient
        (e.g. one period of a periodic force run twice).
    structure : BoucWenStructure
    nu : float, optional
        Fix the exponent at this value (>= 1); ``None`` fits it within ``[1, 4]`` from 1.
    bounded : bool
        Only loops whose ``z`` stays bounded (``beta + gamma >= 0``, ``beta - gamma >= 0``);
        the benchmark's loop stiffens on loading and is outside this class.
    stride : int, default 1
        Model samples per data sample (see `y`).
    discard : int, default 0
        Leading data samples not compared (see `y`).
    max_nfev, screen_nfev, n_polish : int
        As in :func:`~hystkit.identification.fit_multistart`.
    accept : callable, optional
        A candidate counts only if ``accept(params)`` is true; ``accept_reason`` says why others
        were rejected.
    accept_reason : str, optional
        Why candidates were rejected, for the message.
    solver : {"tr", "lm", "trf"}
        See :func:`~hystkit.identification.fit_multistart`. The difference Jacobian is formed
        densely (``n x 7``): the residual's stride, discard and divergence penalty do not split
        into chunks.
    loss, f_scale, weights
        The cost minimised: the SSE by default, or a robust loss and/or per-sample weights
        (one per sample of `y`); see :func:`hystkit.identification.fit_multistart`. Both
        stages minimise it.

    Returns
    -------
    FitResult
        The second stage's result; ``seconds``, ``n_evaluations`` and ``n_starts`` cover both.

    Raises
    ------
    ValueError
        If the data are too short to identify the model: fewer than ``MIN_SAMPLES`` (8)
        samples, a constant output, or a record shorter than one cycle at ``1 / h``.
    FitDivergedError
        If no start gives a finite, non-diverged fit, or every candidate is vetoed.
    """
    u = np.ascontiguousarray(u, dtype=float)
    y = np.ascontiguousarray(y, dtype=float)
    if u.ndim != 1 or y.ndim != 1 or not (np.all(np.isfinite(u)) and np.all(np.isfinite(y))):
        raise ValueError("u and y must be finite 1-D arrays")
    n_out = len(range(0, u.size, stride)) - discard
    if y.size != n_out or n_out < 1:
        raise ValueError(f"y must have len(u[::{stride}]) - {discard} = {n_out} samples, "
                         f"got {y.size}")
    if nu is not None and not nu >= 1:
        raise ValueError(f"nu must be >= 1, got {nu}")
    y_scale = float(np.max(np.abs(y)))
    if y_scale == 0 or not np.any(u):
        raise ValueError("u and y must not be all zero")
    if n_out < MIN_SAMPLES or np.ptp(y) == 0:
        raise ValueError(f"a Bouc-Wen fit needs at least {MIN_SAMPLES} samples (it has 7 "
                         f"parameters) and a varying output, got {n_out} samples with "
                         f"max - min = {np.ptp(y):.3g}")
    lower, upper = parameter_bounds(structure, u[::stride][discard:], y,
                                    u.size * structure.dt, bounded)
    if not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper))
            and np.all(lower < upper)):
        raise ValueError(f"the record is too short to fit a Bouc-Wen model: its "
                         f"{u.size * structure.dt:.3g} s do not span one cycle at the fastest "
                         f"natural frequency 1 / h = {1 / structure.step_size:.3g} rad/s")
    limits = _theta_limits(bounded)
    bound = _PENALTY * y_scale
    penalty = np.full(y.size, bound)
    linear = structure.input_hold == "linear"

    last_divergence: list[str] = []  # what the most recent diverged run did, for the error

    def run(theta: np.ndarray, limit: float) -> np.ndarray | None:
        params = boucwen.BoucWenParams.from_vector(theta)
        x0 = boucwen.initial_state(structure, params, u[0])
        states, x_end, n_bad = kernels.simulate(u, x0, True, params.as_array(), structure.dt,
                                                structure.substeps, linear, limit)
        if n_bad >= 0:
            last_divergence[:] = [boucwen.divergence_message(structure, params, x_end, n_bad,
                                                             u.size, limit)]
            return None
        return states[::stride, 0][discard:]

    def solve(free: np.ndarray, template: np.ndarray, starts: list[np.ndarray],
              **options) -> FitResult:
        """Multi-start fit of the coordinates ``free``, the others held at ``template``."""
        def full(theta: np.ndarray) -> np.ndarray:
            out = template.copy()
            out[free] = theta
            return out

        def residual(theta: np.ndarray) -> np.ndarray:
            y_model = run(full(theta), bound)
            return penalty if y_model is None else y_model - y

        return fit_multistart(residual, [start[free] for start in starts],
                              (lower[free], upper[free]),
                              lambda th: boucwen.BoucWenParams.from_vector(full(th)), structure,
                              max_nfev=max_nfev, screen_nfev=screen_nfev, n_polish=n_polish,
                              solver=solver, loss=loss, f_scale=f_scale, weights=weights,
                              names=[_NAMES[i] for i in free],
                              limits=tuple([side[i] for i in free] for side in limits),
                              **options)

    timer = FitTimer()
    nu_start = 1.0 if nu is None else float(nu)
    # Stage 1: r = 1/2 and beta = gamma = 0 make z = alpha y, a linear oscillator.
    template = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, nu_start])
    lin_starts = _linear_starts(lower, upper, lambda th: run(np.r_[th, template[3:]], np.inf),
                                y)
    if not lin_starts:
        why = (f"every linear start diverged; the last: {last_divergence[0]}"
               if last_divergence else "no linear oscillator follows the data's sign")
        raise FitDivergedError(f"the fit failed: {why}")
    stage1 = solve(np.arange(3), template, [np.r_[th, template[3:]] for th in lin_starts])
    free = np.arange(7 if nu is None else 6)
    stage2 = solve(free, template,
                   _hysteretic_starts(stage1.params.to_vector()[:3], _reference_amplitude(y),
                                      nu_start), accept=accept, accept_reason=accept_reason)
    if not stage2.cost < float(penalty @ penalty):
        raise FitDivergedError(f"the fit failed: the integration diverged from every start "
                               f"(the last: {''.join(last_divergence) or 'no finite cost'})")
    return replace(stage2, seconds=timer.seconds(),
                   n_evaluations=stage1.n_evaluations + stage2.n_evaluations,
                   n_starts=stage1.n_starts + stage2.n_starts)


def fit_family(u: np.ndarray, y: np.ndarray, structure: boucwen.BoucWenStructure, *,
               accept: Callable[[boucwen.BoucWenParams], bool] | None = None,
               accept_reason: str = "rejected by the acceptance test", **options) -> FitResult:
    """The registry's fit on normalised recordings: ``nu = 1`` and bounded, dissipative loops
    unless ``options`` (passed to :func:`fit_boucwen`) say otherwise.

    Unrestricted fits on the virtual sensor chose loops outside that class (stiffening on
    loading or softening on unloading, i.e. ``z`` unbounded), and they generalised worse where
    it mattered most: sine validation R^2 0.875 against 0.938 (docs/models/boucwen.md).

    Parameters
    ----------
    u, y : numpy.ndarray, shape (n,)
        Force and displacement, centred and normalised (eq. 5.10).
    structure : boucwen.BoucWenStructure
        The model's structure.
    accept : callable, optional
        A candidate counts only if ``accept(params)`` is true.
    accept_reason : str, optional
        Why other candidates were rejected, for the message.
    **options
        Passed to :func:`fit_boucwen`.

    Returns
    -------
    FitResult
        As :func:`fit_boucwen`.
    """
    options = {"nu": 1.0, "bounded": True, **options}
    return fit_boucwen(u, y, structure, accept=accept, accept_reason=accept_reason, **options)

