"""Multi-start bounded least squares shared by the model families' fits (eq. 5.9).

The solvers work on normal equations ``(cost, J^T J, J^T r)`` that a family forms in one pass
(its compiled sensitivity kernel, or chunked differences); given only a residual and a
Jacobian (or '2-point'), the normal equations are formed from them:

* ``solver="tr"`` (default): scipy's trust-region reflective on the normal equations
  (:mod:`._trust_region`), the same iterates as before at a cost independent of the Jacobian;
* ``solver="lm"``: a projected Levenberg-Marquardt (:mod:`._lm`);
* ``solver="trf"``: scipy's ``least_squares(method="trf", x_scale="jac")`` on the residual and
  dense Jacobian, kept for comparison and as a fallback.

Beside the SSE a fit can minimise a robust or weighted cost (`fit_multistart`'s ``loss``,
``f_scale``, ``weights``): ``sum_i f^2 rho(w_i r_i^2 / f^2)`` with scipy's ``rho`` (soft_l1,
huber, cauchy; :mod:`._losses`). A robust loss runs on scipy's trf; a weighted SSE keeps
`solver`, on normal equations formed from the residual and Jacobian scaled by ``sqrt(w)`` (the
families' compiled normal equations have no weights). Weighted fits are the folds of
``select`` and of every band's calibration: on scipy's trf they took 1.7-2.8 times the CPU.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np

from .._blas import one_blas_thread
from ..errors import FitDivergedError
from ..parallel import Executor, current_executor
from ._clock import FitTimer
from ._lm import solve_lm
from ._losses import check_cost
from ._normal_equations import NormalEquations, dense_normal_equations
from ._result import FitResult
from ._trust_region import solve_trust_region

__all__ = ["check_fit_data", "check_weights", "fit_multistart"]

_SOLVERS = {"tr": solve_trust_region, "lm": solve_lm, "trf": None}
# When an executor is open, a fit's other starts are screened on its workers if the first
# start's solve took SPLIT_MIN_START or more and all of them together take SPLIT_MIN_SECONDS
# or more (CPU seconds of this thread, which the machine's load does not inflate). A map on a
# local 2-worker Dask cluster costs ~30-60 ms (send the closures and the data, ~130-200 kB at
# 8000 samples, once to each worker; submit; collect), a task ~5 ms more: 0.25 s of starts
# save ~0.12 s on 2 workers, twice that overhead or more. Fits this short stay serial: the
# mPL family, PI, Bobbio at 8000 samples (10-20 ms a start); Chua (~50 ms a start, 7 more
# starts), PL (~90 ms, 11) and Bouc-Wen split. The polishes (up to `max_nfev` evaluations
# each, against `screen_nfev`) of a fit above SPLIT_MIN_START run side by side.
SPLIT_MIN_START = 0.02
SPLIT_MIN_SECONDS = 0.25
# A fit that ran out of budget and whose cost then moves by less than this (relative) over its
# continuation (CONTINUATION) has converged to a flat minimum (:func:`_settle`); 1e-6 is far
# below what separates two models on held-out data (R² differs by ~1e-6 x (1 - R²)).
STALL_RTOL = 1e-6
# Share of the budget a fit that ran out of it gets once more, to settle or show that it
# crawls. Half: the PL fit of the micromanipulator settles within it (a quarter left it "not
# converged"), and the 5-cell mPL on the virtual sine, not converged either way, spends 572
# evaluations instead of 672 with a whole budget more.
CONTINUATION = 0.5


def check_fit_data(u: np.ndarray, y: np.ndarray,
                   min_size: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Fit data ``u``, ``y`` as contiguous float arrays: 1-D, of equal length, finite.

    Parameters
    ----------
    u, y : array_like
        Input and measured output of the fit, one value per sample.
    min_size : int
        Fewest samples accepted (a shorter pair is reported like a length mismatch).

    Returns
    -------
    u, y : ndarray
        The same data as contiguous float64 arrays (copies only where a conversion needs one).

    Raises
    ------
    ValueError
        If the arrays are not 1-D, differ in length, are too short or hold NaN or inf.
    """
    u = np.ascontiguousarray(u, dtype=float)
    y = np.ascontiguousarray(y, dtype=float)
    if u.shape != y.shape or u.ndim != 1 or u.size < min_size:
        raise ValueError(f"u and y must be 1-D and of equal length, got {u.shape} and {y.shape}")
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(y))):
        raise ValueError("u and y must be finite")
    return u, y


def fit_multistart(residual: Callable[[np.ndarray], np.ndarray],
                   starts: Sequence[np.ndarray],
                   bounds: tuple[np.ndarray, np.ndarray],
                   to_params: Callable[[np.ndarray], Any],
                   structure: Any, *,
                   jac: Callable[[np.ndarray], np.ndarray] | str = "2-point",
                   normal_equations: Callable[[np.ndarray], NormalEquations] | None = None,
                   cost: Callable[[np.ndarray], float] | None = None,
                   solver: str = "tr",
                   max_nfev: int = 200, screen_nfev: int = 12, n_polish: int = 2,
                   accept: Callable[[Any], bool] | None = None,
                   accept_reason: str = "rejected by the acceptance test",
                   names: Sequence[str] | None = None,
                   limits: tuple[Sequence[str | None], Sequence[str | None]] | None = None,
                   loss: str = "linear", f_scale: float = 1.0,
                   weights: np.ndarray | None = None,
                   ) -> FitResult:
    """Minimise ``sum(residual(theta)**2)`` (or a robust or weighted cost, see `loss` and
    `weights`) from several starts; return the best as a FitResult.

    Every start first gets ``screen_nfev`` evaluations; the ``n_polish`` cheapest are then run
    to convergence (most starts fall into the same few basins, so polishing all of them would
    repeat work). With ``solver="tr"`` a polish continues its start's solve where the
    screening stopped (radius and scaling go on, its point is not run again), and so does the
    continuation of a best candidate that ran out of budget. ``accept(params)`` can veto a candidate (e.g. an unstable inverse); vetoed
    ones are skipped and counted.

    While a parallel executor is open in this process (`hystkit.parallel.open_executor`), a
    fit whose starts are long enough to pay for it (see `SPLIT_MIN_SECONDS`) screens its other
    starts on the workers, and polishes its first ``n_polish`` candidates side by side there;
    every solve is the same pure function of its start, so the result is the serial one, bit
    for bit (only ``seconds`` differs). Inside a Dask worker no executor is open: a fit that
    is itself one piece of a parallel map stays serial.

    Parameters
    ----------
    residual : callable
        ``theta -> r`` (model output minus target), finite for every ``theta`` inside bounds.
    starts : sequence of arrays
        Initial ``theta`` vectors (clipped into the bounds).
    bounds : (lower, upper)
    to_params : callable
        ``theta -> params`` of the model family.
    structure : object
        The family's structure, stored as ``FitResult.structure``.
    jac : callable or "2-point"
        Exact Jacobian if the family has one, else finite differences.
    normal_equations : callable, optional
        ``theta -> NormalEquations`` (cost ``0.5 sum(r**2)``, ``J^T J``, ``J^T r``) formed
        without the dense Jacobian, for ``solver="tr"`` or ``"lm"``; by default formed from
        ``residual`` and ``jac``.
    cost : callable, optional
        ``theta -> 0.5 sum(r**2)`` alone: trial points are then judged by it, and the normal
        equations formed only where a step is accepted.
    solver : {"tr", "lm", "trf"}
        See the module docstring.
    max_nfev : int
        Evaluation budget of each polishing solve (to convergence or this budget). If the best
        candidate stopped on it, it is continued once with as much again: it converged if
        that meets a termination test or moves the cost by less than ``STALL_RTOL``
        relative (a flat minimum), else it is reported as not converged.
    screen_nfev : int
        Evaluation budget of each start's screening solve.
    n_polish : int
        How many accepted candidates, cheapest first after screening, are polished; the best
        of them is returned.
    accept : callable, optional
        ``params -> bool``; False vetoes a candidate. By default every candidate is accepted.
    accept_reason : str
        Why `accept` vetoes, for the error raised when it vetoes every candidate.
    names : sequence of str, optional
        Names of the ``theta`` coordinates, so that reports name a parameter on a bound
        (``FitResult.bound_hits``) instead of giving its index.
    limits : (lower labels, upper labels), optional
        Which bounds are limits of the model itself rather than of the search box: per
        coordinate a note (``"cell 2 runs at the Euler slope cap"``) or None. A fit that ends
        on such a bound has found a model at its own limit; reports show the note instead of
        calling the fit "on bounds".
    loss : {"linear", "soft_l1", "huber", "cauchy"}
        The cost: ``sum_i f^2 rho(w_i r_i^2 / f^2)`` with scipy's ``rho`` (``least_squares``,
        :func:`hystkit.identification.objective`); "linear" (``rho(z) = z``) with no weights
        is the SSE (eq. 5.9) and the default path.
    f_scale : float
        Residual size ``f`` at which a robust loss leaves the quadratic (scipy's `f_scale`),
        in the units of the residual.
    weights : array, shape (m,), optional
        One weight ``w_i >= 0`` per residual entry (finite, not all zero): the residual and
        Jacobian are scaled by ``sqrt(w)``, and the normal equations formed from them
        (`normal_equations` and `cost` are then not used). A robust loss runs on scipy's trf
        whatever `solver` says.

    Returns
    -------
    FitResult
        The lowest-objective accepted candidate, with its ``cost`` (the plain sum of squared
        residuals, unweighted, whatever the loss), its ``objective`` (the minimised cost, equal
        to ``cost`` for the SSE), the loss, evaluation count, wall time and whether its solver
        converged.

    Raises
    ------
    FitDivergedError
        If no start gives a finite cost, or every candidate is vetoed (the message says why).
    ValueError
        If ``names`` or ``limits`` do not have one entry per coordinate, ``solver`` or
        ``loss`` is unknown, ``f_scale`` is not positive, or ``weights`` are negative, not
        finite, all zero or not one per residual entry.
    """
    if solver not in _SOLVERS:
        raise ValueError(f"solver must be one of {sorted(_SOLVERS)}, got {solver!r}")
    check_cost(loss, f_scale)
    lower, upper = (np.asarray(b, dtype=float) for b in bounds)
    names = _per_coordinate(names, lower.size, "names")
    if limits is not None:
        if len(limits) != 2:
            raise ValueError("limits must be a pair (lower labels, upper labels)")
        limits = (_per_coordinate(limits[0], lower.size, "limits[0]"),
                  _per_coordinate(limits[1], lower.size, "limits[1]"))
    margin = 1e-9 * np.maximum(1.0, upper - lower)
    starts = [np.clip(np.asarray(theta0, dtype=float), lower + margin, upper - margin)
              for theta0 in starts]
    plain_residual = residual
    if weights is not None:
        if not starts:
            raise ValueError("a weighted fit needs at least one start")
        weights = check_weights(weights, plain_residual(starts[0]).size)
        residual, jac = _weighted(residual, jac, np.sqrt(weights))
    if loss != "linear":
        solver, normal_equations, cost = "trf", None, None
    elif weights is not None:  # the family's normal equations have no weights: form them
        normal_equations, cost = None, None  # from the sqrt(w)-scaled residual and Jacobian
    if solver != "trf" and normal_equations is None:
        normal_equations = dense_normal_equations(residual, jac, lower, upper)
        if cost is None and not callable(jac):
            # a difference Jacobian costs n_params runs: judge trial points by the cost alone
            def cost(theta: np.ndarray) -> float:
                r = residual(theta)
                return 0.5 * float(r @ r)

    solve = _StartSolver(residual=residual, jac=jac, normal_equations=normal_equations,
                         cost=cost, solver=solver, lower=lower, upper=upper, margin=margin,
                         loss=loss, f_scale=float(f_scale))
    timer = FitTimer()
    screened, executor = _screen(solve, starts, screen_nfev)
    n_eval = sum(sol.n_runs for sol in screened)
    screened = sorted((sol for sol in screened if np.isfinite(sol.cost)),
                      key=lambda sol: sol.cost)
    # The first n_polish candidates are polished whatever happens (the loop below stops only
    # after n_polish accepted ones): on workers they run side by side, ahead of the loop.
    polished = _solve_on(executor, solve, [(sol.x, sol.state) for sol in screened[:n_polish]
                                            if sol.status == 0], max_nfev)
    waiting = iter(range(len(polished)))
    best, rejected, n_polished = None, 0, 0
    for sol in screened:
        if best is not None and n_polished >= n_polish:
            break
        if sol.status == 0:  # budget ran out: continue from where it stopped
            i = next(waiting, None)
            sol = polished[i] if i is not None else solve(sol.x, max_nfev, sol.state)
            n_eval += sol.n_runs
        if not np.isfinite(sol.cost):
            continue
        if accept is not None and not accept(to_params(sol.x)):
            rejected += 1
            continue
        n_polished += 1
        if best is None or sol.cost < best.cost:
            best = sol
    if best is None:
        why = (f"all {rejected} candidate fits were rejected ({accept_reason})" if rejected
               else "no start gave a finite cost")
        raise FitDivergedError(f"the fit failed: {why}")
    best, converged, message, extra = _settle(solve, best, max_nfev, to_params, accept)
    n_eval += extra
    objective = 2.0 * float(best.cost)
    sse = objective
    if solve.loss != "linear" or weights is not None:
        # the plain SSE of the final residuals, for R^2 and information criteria
        r = plain_residual(best.x)
        sse = float(r @ r)
    return FitResult(structure=structure, params=to_params(best.x), cost=sse,
                     objective=objective, loss=loss, f_scale=float(f_scale),
                     weighted=weights is not None,
                     n_evaluations=int(n_eval), seconds=timer.seconds(),
                     converged=converged, message=message,
                     n_starts=len(starts), theta=np.array(best.x),
                     bounds=(lower, upper), names=names, limits=limits,
                     sensitivity=best.column_norms)


def _settle(solve: Callable, best: SimpleNamespace, max_nfev: int, to_params: Callable,
            accept: Callable | None) -> tuple[SimpleNamespace, bool, str, int]:
    """``(best, converged, message, evaluations spent)``: a best candidate that stopped on its
    budget is continued once with ``CONTINUATION`` of it. It converged if the continuation meets a
    termination test, or if the cost moved by less than ``STALL_RTOL`` relative: the solver
    then crawls along a flat valley (parameters the data do not separate, e.g. two cells
    whose weights cancel), where more evaluations change the model's output by nothing; the
    point where the budget ran out is kept, and the standard errors say which parameters
    are not determined."""
    if best.status > 0:
        return best, True, str(best.message), 0
    more = solve(best.x, max(1, round(CONTINUATION * max_nfev)), best.state)
    better = (np.isfinite(more.cost) and more.cost <= best.cost
              and (accept is None or accept(to_params(more.x))))
    change = (best.cost - more.cost) / max(best.cost, 1e-300) if better else 0.0
    chosen = more if better else best
    if better and more.status > 0:
        return chosen, True, str(more.message), more.n_runs
    if change < STALL_RTOL:
        # keep the point where the cost stopped improving: further along the valley the
        # parameters only grow more extreme (weights that cancel), the output does not change
        return best, True, (f"the cost moved by {change:.1e} relative over {more.n_runs} more "
                            f"evaluations: converged to a flat minimum (the budget ran out "
                            f"while the parameters crawled along it)"), more.n_runs
    return chosen, False, str(more.message if better else best.message), more.n_runs


@dataclass(frozen=True)
class _StartSolver:
    """One start's bounded solve, ``(theta0, budget[, resume]) -> SimpleNamespace(x, cost,
    status, message, n_runs, column_norms, state)``; a pure function of its arguments, so a
    worker process that gets a copy (closures travel by cloudpickle) returns what this process
    would. ``resume``, an earlier result's ``state`` (solver "tr" only, else None), continues
    that solve where it stopped instead of starting again from ``theta0``: its last point is
    not run again and its radius and scaling go on. The budget counts as for a restart from
    that point, whose first evaluation (the point itself) the resumed solve saves: it takes
    the same number of new steps, one run fewer."""

    residual: Callable[[np.ndarray], np.ndarray]
    jac: Callable[[np.ndarray], np.ndarray] | str
    normal_equations: Callable[[np.ndarray], NormalEquations] | None
    cost: Callable[[np.ndarray], float] | None
    solver: str
    lower: np.ndarray
    upper: np.ndarray
    margin: np.ndarray
    loss: str = "linear"
    f_scale: float = 1.0

    def __call__(self, theta0: np.ndarray, budget: int, resume: Any = None) -> SimpleNamespace:
        # BLAS threads do not pay on (n x n_params) problems, and under load they cost 10-30x
        # (benchmarks/README.md).
        with one_blas_thread():
            if self.solver != "trf":
                # lm may stop on a bound, the margin keeps it inside as trf and tr stay
                shrink = self.margin if self.solver == "lm" else 0.0
                if resume is not None:
                    budget, more = budget - 1, {"resume": resume}
                else:
                    more = {}
                sol = _SOLVERS[self.solver](self.normal_equations, theta0, self.lower + shrink,
                                            self.upper - shrink, cost=self.cost,
                                            max_nfev=budget, **more)
                return SimpleNamespace(x=sol.x, cost=sol.cost, status=sol.status,
                                       message=sol.message, n_runs=sol.n_runs,
                                       column_norms=sol.column_norms, state=sol.state)
            from scipy.optimize import least_squares  # here: ~0.4 s to import, trf only

            sol = least_squares(self.residual, theta0, jac=self.jac,
                                bounds=(self.lower, self.upper), method="trf", x_scale="jac",
                                loss=self.loss, f_scale=self.f_scale, max_nfev=budget)
        # Keep only what ranking and reporting need: the (n x n_params) Jacobian and the
        # residuals of every screened start alive together cost GBs on long recordings.
        return SimpleNamespace(x=sol.x, cost=float(sol.cost), status=sol.status,
                               message=sol.message, n_runs=sol.nfev + (sol.njev or 0),
                               column_norms=_column_norms(sol.jac), state=None)


def _screen(solve: _StartSolver, thetas: list[np.ndarray],
            budget: int) -> tuple[list[SimpleNamespace], Executor | None]:
    """Every start's screening solve, in order, and the executor the polish may use (None
    for a fit whose first start took less than `SPLIT_MIN_START`).

    The first start runs here, timed; if it and the others at its cost would take long
    enough (`SPLIT_MIN_START`, `SPLIT_MIN_SECONDS`) and an executor is open
    (`hystkit.parallel.current_executor`), the other starts run on its workers (at least two
    of them: one would only wait for the other), else here after it.
    """
    executor = current_executor()
    if executor is None or len(thetas) < 3:
        return [solve(theta, budget) for theta in thetas], None
    t0 = time.thread_time()
    first = solve(thetas[0], budget)
    seconds = time.thread_time() - t0
    if seconds < SPLIT_MIN_START:
        return [first, *(solve(theta, budget) for theta in thetas[1:])], None
    if seconds * (len(thetas) - 1) < SPLIT_MIN_SECONDS:  # polishes still pay: longer
        return [first, *(solve(theta, budget) for theta in thetas[1:])], executor
    return [first, *_solve_on(executor, solve, [(theta, None) for theta in thetas[1:]],
                              budget)], executor


def _solve_on(executor: Executor | None, solve: _StartSolver, starts: list[tuple],
              budget: int) -> list[SimpleNamespace]:
    """``[solve(theta, budget, resume) for theta, resume in starts]``, on `executor`'s
    workers if given and there are two or more."""
    if executor is None or len(starts) < 2:
        return [solve(theta, budget, resume) for theta, resume in starts]
    return executor.map(_solve_start, [(theta, budget, resume) for theta, resume in starts],
                        shared={"solve": solve})


def _solve_start(start: tuple[np.ndarray, int, Any], *,
                 solve: _StartSolver) -> SimpleNamespace:
    """One piece of a parallel multi-start (module level: a worker finds it by name)."""
    return solve(*start)


MAX_WEIGHT = 1e100
"""Largest per-sample weight a fit takes: above it ``w r^2`` and the weights' sums overflow
(1e308 gives inf in numpy and illegal values in LAPACK). Only ratios of weights matter to the
SSE, so a column of larger numbers can be rescaled by the user."""


def check_weights(weights: Any, size: int) -> np.ndarray:
    """Per-residual weights as a float array: 1-D, ``size`` entries, finite, in
    ``[0, MAX_WEIGHT]``, not all 0.

    Parameters
    ----------
    weights : array_like
        One weight per residual entry.
    size : int
        The residual's length.

    Returns
    -------
    ndarray
        The weights as a contiguous float64 array.

    Raises
    ------
    ValueError
        Naming the first offending entry (0-based) or the lengths.
    """
    weights = np.ascontiguousarray(weights, dtype=float)
    if weights.ndim != 1 or weights.size != size:
        raise ValueError(f"weights must have one entry per residual entry ({size}), got "
                         f"shape {weights.shape}")
    bad = np.flatnonzero(~(np.isfinite(weights) & (weights >= 0) & (weights <= MAX_WEIGHT)))
    if bad.size:
        raise ValueError(f"weights must be finite, >= 0 and <= {MAX_WEIGHT:g}, entry {bad[0]} "
                         f"is {float(weights[bad[0]])!r}")
    if not np.any(weights > 0):
        raise ValueError("weights must not all be zero")
    return weights


def _weighted(residual: Callable[[np.ndarray], np.ndarray],
              jac: Callable[[np.ndarray], np.ndarray] | str,
              root: np.ndarray) -> tuple[Callable, Callable | str]:
    """Residual and Jacobian scaled by ``root = sqrt(w)`` row by row ("2-point" stays so:
    differences of the scaled residual are the scaled Jacobian)."""
    def scaled_residual(theta: np.ndarray) -> np.ndarray:
        return root * residual(theta)

    if not callable(jac):
        return scaled_residual, jac

    def scaled_jac(theta: np.ndarray) -> np.ndarray:
        return root[:, None] * jac(theta)

    return scaled_residual, scaled_jac


def _column_norms(jac: Any) -> np.ndarray | None:
    """Column norms of the solver's Jacobian at the optimum (None if it has none)."""
    if jac is None:
        return None
    jac = jac.toarray() if hasattr(jac, "toarray") else np.asarray(jac, dtype=float)
    return np.linalg.norm(jac, axis=0) if jac.ndim == 2 else None


def _per_coordinate(values: Sequence | None, n: int, what: str) -> tuple | None:
    if values is None:
        return None
    values = tuple(values)
    if len(values) != n:
        raise ValueError(f"{what} must have one entry per coordinate ({n}), got {len(values)}")
    return values

