"""Least-squares identification of the mPL model (sec. 5.3.2, cost eq. 5.9).

The document minimised the SSE with fmincon / patternsearch for about a minute. Here the same
cost goes to the bounded trust-region solver of ``hystkit.identification`` (scipy's trf steps)
with exact normal equations ``J^T J``, ``J^T r`` accumulated in one pass of the forward
sensitivities of the Euler recursion (``kernels.normal_equations``; the ``n x p`` Jacobian is
never stored), from a few deterministic starts (``solver="trf"``: scipy's trust-region
reflective on the dense Jacobian).
Each start sets the cell time constants and gets its linear parameters (``w``, ``V_b``, which
enter the output linearly) by linear least squares, so no start begins far off. A 1-cell fit
goes further (:class:`~.projection.Projection`, issue 29.5): its multi-start moves the cell's
shape only, with the best weights at every point, and full solves from the best finish it.

The document's own setups (sec. 5.3.3) are options: ``init`` starts from one given parameter
set only (table 5.2's initial conditions), ``weight_sum_max`` adds fmincon's constraint
``sum |w| <= B`` (:mod:`hystkit.identification._constrained`), and a structure with
``limit=False`` fits the unbounded sinh, whose box then has no Euler bound on ``G``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from types import SimpleNamespace

import numpy as np

from ..._kernel_inputs import read_only
from ...identification import FitResult, NormalEquations, check_fit_data, fit_multistart
from ...identification._constrained import constrain_fit
from . import kernels
from . import model as mpl
from .box import (
    LOG_G_MIN,
    LOG_G_UNLIMITED,
    LOG_VT_BOUNDS,
    W_BOUND,
    fit_box,
    random_params,
    theta_names,
)
from .projection import Projection

__all__ = ["default_starts", "fit_box", "fit_mpl", "random_params", "theta_limits",
           "theta_names"]


def _linear_init(structure: mpl.MplStructure, i_s: np.ndarray, v_t: np.ndarray,
                 u: np.ndarray, y: np.ndarray) -> mpl.MplParams:
    """Given cell resistors, the best weights and bias by linear least squares.

    With ``w = 0``, ``V_b = 0`` the model output is 0, so ``r = -y`` and the normal equations'
    block of the linear columns (``[u, x_1..x_N, -1]``) gives ``coef = -(J_l^T J_l)^+ J_l^T r``.
    """
    probe = mpl.MplParams(i_s=i_s, v_t=v_t, w=np.zeros(structure.n_cells + 1))
    knee = mpl.knee_voltage(structure, probe)
    _, jtj, jtr = kernels.normal_equations(u, y, np.full(structure.n_cells, u[0]), probe.i_s,
                                           probe.v_t, probe.w, 0.0, knee,
                                           structure.slope_cap / structure.dt, structure.dt)
    lin = slice(2 * structure.n_cells, None)
    coef = -np.linalg.lstsq(jtj[lin, lin], jtr[lin], rcond=None)[0]
    coef[:-1] = np.clip(coef[:-1], -0.9 * W_BOUND, 0.9 * W_BOUND)
    return mpl.MplParams(i_s=i_s, v_t=v_t, w=coef[:-1], v_b=coef[-1])


# Fits of at most this many cells search the cells' shapes with the weights projected out
# (Projection): each start screened with PROJECTED_SCREEN runs, the best PROJECTED_POLISH run
# to convergence, then one or two full solves. Measured at 1 cell on the benchmark's sine and
# 53 real runs (MR damper, piezo, Bouc-Wen, B(H) loops), against the full search: fewer runs
# on every one (25-60 instead of 72-114; 36-330 instead of 89-569 on the B(H) loops, two of
# which now converge); SSE lower on 50, higher by 2e-11 to 4e-10 relative on three. With one
# polish, two recordings fitted end to end (the virtual sine, seed 1, and decay, seed 2) ended
# at a linear cell on the V_T bound, 15 % above the full search's SSE: the second-best start
# is polished too (39 runs there instead of 26; tests/models/mpl/test_mpl_fit.py). At 3 cells
# the projected search found other minima: lower on five of seven data sets but 0.7 % higher
# on one, and with weights on their box (a refused fit) where the full search had none, so
# fits of more cells keep the full search (benchmarks/last_run_fit_cost.txt).
PROJECTED_CELLS = 1
PROJECTED_SCREEN = 3
PROJECTED_POLISH = 2
def _projected_search(normal_equations: Callable[[np.ndarray], NormalEquations],
                      starts: list[tuple[np.ndarray, np.ndarray]],
                      structure: mpl.MplStructure, box: tuple[np.ndarray, np.ndarray],
                      to_params: Callable[[np.ndarray], mpl.MplParams], solver: str,
                      options: dict) -> SimpleNamespace:
    """The multi-start over the cells' shapes with the weights projected out
    (:class:`Projection`): ``theta`` (its best, with its weights), ``runs`` and ``seconds``."""
    m = 2 * structure.n_cells
    lower, upper = box
    projected = Projection(normal_equations, structure.n_cells, lower[m:], upper[m:])
    shapes = [np.column_stack([np.log(2 * np.asarray(i_s, float) / np.asarray(v_t, float)),
                               np.log(np.asarray(v_t, float))]).reshape(-1)
              for i_s, v_t in starts]  # (log G, log V_T) per cell, as in theta
    best = fit_multistart(projected.no_residual, shapes, (lower[:m], upper[:m]),
                          lambda cells: to_params(projected.full(cells)), structure,
                          jac=projected.no_residual, normal_equations=projected, solver=solver,
                          **{**options,
                             "screen_nfev": min(options["screen_nfev"], PROJECTED_SCREEN),
                             "n_polish": min(options["n_polish"], PROJECTED_POLISH)})
    theta = projected.full(best.theta)
    # runs: the solver's evaluations (the second pass of a near-exact one, and the pass for a
    # point a worker evaluated, are not counted: they happen in whichever process ran it, and
    # a fit split over workers counts the same as a serial one)
    return SimpleNamespace(theta=theta, runs=best.n_evaluations,
                           seconds=best.seconds)

# A cell whose rate G at the floor moves it by less than this share of its drive over the whole
# record integrates: only w_k G_k is identified, and a smaller G with a larger w is the same
# model over the record (the floor is then a limit of what the data can tell, not a box).
_INTEGRATING = 0.1


def theta_limits(n_cells: int, limit: bool = True,
                 duration: float | None = None) -> tuple[list[str | None], list[str | None]]:
    """Which bounds are the model's own limits, with a note for each (see ``fit_multistart``).

    The criterion: moving past the bound cannot change the model's output, so a fit there has
    found a valid model at a limit of the family, not a search box that is too small.

    * Upper bound of ``log G_k`` (``G_k = 2 I_S / V_T``, the cell's small-signal slope):
      ``slope_cap / dt`` is the Euler stability limit (eq. 5.28-5.29). At and beyond it the
      knee voltage is 0 and the limited resistor is the straight line of slope ``slope_cap /
      dt`` whatever ``G_k`` is: exactly the same model.
    * Upper bound of ``log V_T,k`` (1e3): at fixed ``G_k`` the resistor ``G V_T sinh(v / V_T)``
      tends to the linear ``G v`` as ``V_T -> inf``; at 1e3 it differs from that limit by
      ``(v / V_T)^2 / 6 < 1e-6`` relative for the normalised data (|v| <= 2, eq. 5.10), so the
      bound stands for a linear cell resistor.

    * Lower bound of ``log G_k`` (1e-4 /s), for a record of `duration` with ``G_min duration
      <= 0.1``: over the record such a cell moves by at most a tenth of its drive, so it acts
      as an integrator whose output depends on ``w_k G_k`` only; a slower cell with a larger
      weight is the same model over the record (a redundant time constant, not a box too
      small).

    Every other bound (``G_k`` at its floor on a longer record, ``V_T`` at 1e-3, ``|w| =
    100``) is a search box: past it the model changes, and a fit there is reported as on
    bounds. Without the limit (``limit=False``) the upper bound of ``log G_k`` is a search
    box too.
    """
    lower: list[str | None] = [None] * (3 * n_cells + 2)
    upper = list(lower)
    g_floor = float(np.exp(LOG_G_MIN if limit else LOG_G_UNLIMITED[0]))
    for k in range(n_cells):
        if duration is not None and g_floor * duration <= _INTEGRATING:
            lower[2 * k] = (f"cell {k + 1} integrates over the record (time constant 1/G >= "
                            f"{1 / g_floor:.3g} s against {duration:.3g} s of data): only "
                            f"w[{k + 1}] G[{k + 1}] is identified")
        if limit:
            upper[2 * k] = (f"cell {k + 1} runs at the Euler slope cap (G dt = slope_cap, "
                            f"eq. 5.28-5.29)")
        upper[2 * k + 1] = (f"cell {k + 1} has a linear resistor (V_T at its bound "
                            f"{np.exp(LOG_VT_BOUNDS[1]):g} stands for V_T -> inf)")
    return lower, upper


def default_starts(structure: mpl.MplStructure) -> list[tuple[np.ndarray, np.ndarray]]:
    """Deterministic (I_S, V_T) starts: cell time constants spread over decades.

    Cell rates ``G = 2 I_S / V_T`` start at geometric spreads around 0.3, 3 and 30 per cent of
    the Euler cap, with a strongly (V_T = 0.2, the document's initial value) and a mildly
    (V_T = 2) non-linear resistor, for data normalised to max |.| = 1 (eq. 5.10).

    Parameters
    ----------
    structure : MplStructure
        The model's structure (cell count, ``dt`` and slope cap set the rates).

    Returns
    -------
    list of (numpy.ndarray, numpy.ndarray)
        Six ``(i_s, v_t)`` pairs, each of shape (N,), with every ``G`` at most 0.9 of the cap.
    """
    g_max = structure.slope_cap / structure.dt
    k = np.arange(structure.n_cells)
    starts = []
    for v_t in (0.2, 2.0):
        for frac in (0.003, 0.03, 0.3):
            g = g_max * frac * 6.0 ** (k - (structure.n_cells - 1) / 2)
            g = np.minimum(g, 0.9 * g_max)
            v = np.full(structure.n_cells, v_t)
            starts.append((0.5 * g * v, v))
    return starts


def fit_mpl(u: np.ndarray, y: np.ndarray, structure: mpl.MplStructure, *,
            starts: list[tuple[np.ndarray, np.ndarray]] | None = None,
            max_nfev: int = 200, screen_nfev: int = 12, n_polish: int = 2,
            accept: Callable[[mpl.MplParams], bool] | None = None,
            accept_reason: str = "rejected by the acceptance test",
            solver: str = "tr", loss: str = "linear", f_scale: float = 1.0,
            weights: np.ndarray | None = None, init: mpl.MplParams | None = None,
            weight_sum_max: float | None = None) -> FitResult:
    """Fit an mPL model mapping ``u`` to ``y`` by minimising the SSE (eq. 5.9).

    Parameters
    ----------
    u, y : array, shape (n,)
        Model input and target output, sampled every ``structure.dt``, already centred and
        normalised (eq. 5.10) by the caller.
    structure : MplStructure
        Cell count, sample time and Euler slope cap of the model to fit.
    starts : list of (i_s, v_t) pairs, optional
        Initial resistor shapes; the default is :func:`default_starts`.
    max_nfev : int
        Residual-evaluation budget when polishing one start.
    screen_nfev, n_polish : int
        Every start first gets ``screen_nfev`` evaluations; the ``n_polish`` best are then run
        to convergence. The projected search of a 1-cell fit screens with at most
        ``PROJECTED_SCREEN``, polishes at most ``PROJECTED_POLISH`` and ends with one or two
        full solves from its best.
    accept : callable, optional
        A candidate solution counts only if ``accept(params)`` is true (inverse mode uses it to
        require a bounded inverse).
    accept_reason : str
        Says in the error message why candidates were rejected by `accept`.
    solver : {"tr", "lm", "trf"}
        See :func:`hystkit.identification.fit_multistart`.
    loss, f_scale, weights
        The cost minimised: the SSE by default, or a robust loss and/or per-sample weights
        (one per sample of ``y``); see :func:`hystkit.identification.fit_multistart`.
    init : MplParams, optional
        Start from exactly these parameters and from them only (the document's single fmincon
        start, table 5.2); `starts` is then ignored. Coordinates outside :func:`fit_box` are
        clipped into it.
    weight_sum_max : float, optional
        Constrain ``sum_k |w_k| <= weight_sum_max`` (fmincon's constraint, ``B = 100`` in
        sec. 5.3.3): the multi-start's best is carried on to the constrained optimum
        (:func:`hystkit.identification._constrained.constrain_fit`); SSE only.

    Returns
    -------
    FitResult
        The lowest-cost accepted candidate's :class:`MplParams`, its SSE, whether it converged,
        and the optimiser coordinates, bounds and bound notes (:func:`theta_limits`).

    Raises
    ------
    ValueError
        If `u` and `y` are not 1-D, differ in length or are not finite, `solver` is unknown,
        `init` has another number of cells, or `weight_sum_max` is given with a robust loss or
        weights.
    FitDivergedError
        If no start gives a finite cost, or `accept` rejects every candidate.
    """
    u, y = check_fit_data(u, y)
    n = structure.n_cells
    cap = structure.slope_cap / structure.dt
    x0 = np.full(n, u[0])
    lower, upper = fit_box(structure)
    starts = default_starts(structure) if starts is None else starts
    cache: dict = {}

    def kernel_args(theta: np.ndarray) -> tuple:
        # MplParams.from_vector's arithmetic without its validation (bounds keep theta in the
        # domain), for the trf path; normal_equations does the same in compiled code
        cells = theta[: 2 * n].reshape(n, 2)
        v_t = np.exp(cells[:, 1])
        resistors = SimpleNamespace(i_s=0.5 * np.exp(cells[:, 0]) * v_t, v_t=v_t)
        # read-only, as MplParams' arrays: one specialisation of the kernels for fit and model
        return (read_only(resistors.i_s), read_only(v_t),
                read_only(np.ascontiguousarray(theta[2 * n: 3 * n + 1])),
                float(theta[3 * n + 1]), mpl.knee_voltage(structure, resistors), cap,
                structure.dt)

    def run(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # least_squares (solver="trf") asks for the residual and then the Jacobian at the same
        # point: the sensitivity kernel yields both in one pass.
        key = theta.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = kernels.simulate_with_jacobian(u, x0, *kernel_args(theta))
        return cache[key]

    # Trial points get the normal equations too (no cost-only runs): a one-pass run costs
    # 0.6-0.9 simulations (its sinh from one exp, kernels.sinh_cosh) and ~17 % of trial steps
    # are rejected, so a cost-only trial (a simulation) plus a pass at every accepted point
    # would cost more.
    def normal_equations(theta: np.ndarray) -> NormalEquations:
        if not structure.limit:  # the compiled theta version always applies the limit
            sse, jtj, jtr = kernels.normal_equations(u, y, x0, *kernel_args(theta))
        else:
            sse, jtj, jtr = kernels.theta_normal_equations(u, y, x0, theta,
                                                           structure.slope_cap, structure.dt)
        return NormalEquations(0.5 * sse, jtj, jtr)

    def to_params(theta: np.ndarray) -> mpl.MplParams:
        return mpl.MplParams.from_vector(theta, n)

    options = {"max_nfev": max_nfev, "screen_nfev": screen_nfev, "n_polish": n_polish,
               "accept": accept, "accept_reason": accept_reason}
    search = None
    if init is not None:
        if init.n_cells != n:
            raise ValueError(f"init has {init.n_cells} cell(s), the structure {n}")
        thetas = [init.to_vector()]
    elif n > PROJECTED_CELLS or solver == "trf" or loss != "linear" or weights is not None:
        thetas = [_linear_init(structure, np.asarray(i_s, float), np.asarray(v_t, float), u,
                               y).to_vector() for i_s, v_t in starts]
    else:
        search = _projected_search(normal_equations, starts, structure, (lower, upper),
                                   to_params, solver, options)
        thetas = [search.theta]
        options["n_polish"] = 1  # from the projected optimum: a few runs to the full one

    def full_fit(thetas: list[np.ndarray]) -> FitResult:
        return fit_multistart(lambda th: run(th)[0] - y, thetas, (lower, upper), to_params,
                              structure, jac=lambda th: run(th)[1],
                              normal_equations=normal_equations, solver=solver, **options,
                              names=theta_names(n),
                              limits=theta_limits(n, structure.limit, u.size * structure.dt),
                              loss=loss, f_scale=f_scale, weights=weights)

    result = full_fit(thetas)
    if search is not None:
        runs, seconds = search.runs + result.n_evaluations, search.seconds + result.seconds
        if result.converged:
            # ftol stops a solve whose step gains < 1e-8 relative; along a flat valley a
            # restart's first step halves what is left (benchmark, 128k samples: 4.3e-9 above
            # the minimum, then 2.1e-9; the full search ended at 1.7e-9), for 2 runs
            again = full_fit([result.theta])
            runs, seconds = runs + again.n_evaluations, seconds + again.seconds
            result = again if again.cost <= result.cost else result
        result = dataclasses.replace(result, n_evaluations=runs, seconds=seconds,
                                     n_starts=len(starts))
    if weight_sum_max is None:
        return result
    return constrain_fit(result, normal_equations, np.arange(2 * n, 3 * n + 1),
                         weight_sum_max, to_params, accept=accept, accept_reason=accept_reason)
