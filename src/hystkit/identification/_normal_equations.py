"""Normal equations ``(cost, J^T J, J^T r)`` for :func:`~._lm.solve_lm`, for families without
a one-pass compiled kernel.

* :func:`dense_normal_equations`: from a residual and a dense Jacobian (the family's own, or
  forward differences), ``O(n_samples x n_params)`` memory as before, without scipy's copies.
* :class:`ChunkedDifferences`: forward differences formed chunk by chunk. The base and the
  ``p`` perturbed parameter sets are run over one chunk each, every run carrying its own state
  into the next chunk (a split run equals the whole run for every family), and ``J^T J``,
  ``J^T r`` are accumulated per chunk, so memory is ``O(chunk x n_params)`` whatever the
  recording's length.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["STATUS_MESSAGES", "ChunkedDifferences", "NormalEquations", "RunCounter",
           "SolveResult", "dense_normal_equations", "difference_steps"]

_REL_STEP = np.finfo(float).eps ** 0.5  # scipy's '2-point' relative step
CHUNK = 65_536  # samples per chunk: (p + 1) runs of this many samples stay a few MB


@dataclass(frozen=True)
class NormalEquations:
    """A least-squares problem's local model at one point.

    Parameters
    ----------
    cost : float
        ``0.5 * sum(r**2)`` (scipy's convention).
    jtj : array, shape (p, p)
        ``J^T J``, symmetric.
    jtr : array, shape (p,)
        ``J^T r``, the gradient of ``cost``.
    """

    cost: float
    jtj: np.ndarray
    jtr: np.ndarray


# SolveResult.message of each status, as scipy words them (-2 only LM reaches)
STATUS_MESSAGES = {
    -3: "the cost is not finite at the start",
    -2: "stalled: no step lowered the cost (damping exceeded 1e16) before xtol was met",
    0: "budget exhausted: the maximum number of function evaluations was reached",
    1: "gtol termination condition is satisfied",
    2: "ftol termination condition is satisfied",
    3: "xtol termination condition is satisfied",
    4: "both ftol and xtol termination conditions are satisfied",
}


@dataclass(frozen=True)
class SolveResult:
    """Outcome of :func:`~._lm.solve_lm` or :func:`~._trust_region.solve_trust_region`
    (field names as scipy's ``OptimizeResult``).

    Parameters
    ----------
    x : numpy.ndarray, shape (p,)
        The final point (the start, moved into the box, if no step was accepted).
    cost : float
        ``0.5 * sum(r**2)`` at ``x`` (inf if the start was not finite).
    status : int
        -3 no finite start, -2 stalled (LM only), 0 budget exhausted, 1 gtol, 2 ftol, 3 xtol,
        4 ftol and xtol.
    message : str
        What ``status`` means, in words.
    nfev, njev, n_runs : int
        Cost evaluations, normal-equation formations and model runs, see :class:`RunCounter`
        (the budget ``max_nfev`` applies to ``nfev``, as in scipy).
    column_norms : numpy.ndarray, shape (p,), or None
        ``sqrt(diag(J^T J))`` at ``x``; None when the start was not finite.
    state : object, optional
        What the solver needs to continue from ``x`` with more budget (its ``resume``
        argument) as if it had not stopped; None if it cannot.
    """

    x: np.ndarray
    cost: float
    status: int
    message: str
    nfev: int
    njev: int
    n_runs: int
    column_norms: np.ndarray | None
    state: Any = None

    @property
    def success(self) -> bool:
        return self.status > 0


class RunCounter:
    """Counts as scipy does: ``nfev`` cost evaluations (trial points and the start), ``njev``
    normal-equation formations; ``n_runs`` model runs (a run that yields both counts once)."""

    def __init__(self) -> None:
        self.nfev = self.njev = self.n_runs = 0

    def trial(self, normal_equations, x) -> NormalEquations:
        """Cost and normal equations at a trial point from one run."""
        self.nfev += 1
        self.njev += 1
        self.n_runs += 1
        return normal_equations(x)

    def normal(self, normal_equations, x) -> NormalEquations:
        """Normal equations at an accepted point whose cost was judged alone."""
        self.njev += 1
        self.n_runs += 1
        return normal_equations(x)

    def cost(self, cost, x) -> float:
        self.nfev += 1
        self.n_runs += 1
        return float(cost(x))


def difference_steps(x: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Forward-difference steps as scipy's '2-point': ``sqrt(eps) max(1, |x_i|)`` with the
    sign of ``x_i``, flipped where the step would leave the box; exactly representable."""
    sign = np.where(x >= 0, 1.0, -1.0)
    h = _REL_STEP * sign * np.maximum(1.0, np.abs(x))
    outside = (x + h > upper) | (x + h < lower)
    h = np.where(outside, -h, h)
    return (x + h) - x


def dense_normal_equations(residual: Callable[[np.ndarray], np.ndarray],
                           jac: Callable[[np.ndarray], np.ndarray] | str,
                           lower: np.ndarray, upper: np.ndarray,
                           ) -> Callable[[np.ndarray], NormalEquations]:
    """``x -> NormalEquations`` from ``residual(x)`` and ``jac(x)`` (or '2-point' differences).

    Parameters
    ----------
    residual : callable
        ``x -> r``, shape (n,).
    jac : callable or str
        ``x -> J``, shape (n, p); anything else (``"2-point"``) means forward differences with
        scipy's steps.
    lower, upper : numpy.ndarray, shape (p,)
        Bounds; difference steps are flipped where they would leave the box.

    Returns
    -------
    callable
        ``x -> NormalEquations``; a point whose cost is not finite gets ``cost = inf`` (and
        NaN ``J^T J``, ``J^T r``), which the solvers reject.
    """

    def normal_equations(x: np.ndarray) -> NormalEquations:
        r = residual(x)
        cost = 0.5 * float(r @ r)
        if not np.isfinite(cost):
            return _rejected(x.size)
        if callable(jac):
            j = np.asarray(jac(x), dtype=float)
        else:
            steps = difference_steps(x, lower, upper)
            j = np.empty((r.size, x.size))
            for i, step in enumerate(steps):
                shifted = x.copy()
                shifted[i] += step
                j[:, i] = (residual(shifted) - r) / step
        return NormalEquations(cost, j.T @ j, j.T @ r)

    return normal_equations


class ChunkedDifferences:
    """Cost and forward-difference normal equations of ``simulate(theta, u) - y`` by chunks.

    Parameters
    ----------
    simulate : callable
        ``(theta, u_chunk, x_start) -> (y_chunk, x_end)``: the model run over a chunk from
        state ``x_start`` (``None`` for the family's start at ``u[0]``), returning its end state.
    u, y : arrays, shape (n,)
        Input and target.
    lower, upper : arrays, shape (p,)
        The optimiser's bounds (difference steps stay inside).
    chunk : int
        Samples per chunk.
    """

    def __init__(self, simulate: Callable[[np.ndarray, np.ndarray, Any], tuple],
                 u: np.ndarray, y: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                 chunk: int = CHUNK) -> None:
        self.simulate = simulate
        self.u, self.y = u, y
        self.lower, self.upper = np.asarray(lower, float), np.asarray(upper, float)
        self.chunk = int(chunk)

    def cost(self, theta: np.ndarray) -> float:
        """``0.5 * sum(r**2)``; inf if the run is not finite."""
        total, state = 0.0, None
        for start in range(0, self.u.size, self.chunk):
            stop = min(start + self.chunk, self.u.size)
            out, state = self.simulate(theta, self.u[start:stop], state)
            r = out - self.y[start:stop]
            total += float(r @ r)
        return 0.5 * total if np.isfinite(total) else np.inf

    def normal_equations(self, theta: np.ndarray) -> NormalEquations:
        """Cost, ``J^T J`` and ``J^T r`` with ``J`` by forward differences, chunk by chunk."""
        theta = np.asarray(theta, dtype=float)
        steps = difference_steps(theta, self.lower, self.upper)
        shifted = [theta] + [theta + step * e for step, e in zip(steps, np.eye(theta.size))]
        states: list[Any] = [None] * len(shifted)
        p = theta.size
        jtj, jtr, total = np.zeros((p, p)), np.zeros(p), 0.0
        j = np.empty((min(self.chunk, self.u.size), p))
        for start in range(0, self.u.size, self.chunk):
            stop = min(start + self.chunk, self.u.size)
            base, states[0] = self.simulate(theta, self.u[start:stop], states[0])
            r = base - self.y[start:stop]
            jc = j[:stop - start]
            for i in range(p):
                out, states[i + 1] = self.simulate(shifted[i + 1], self.u[start:stop],
                                                   states[i + 1])
                # differences of residuals, not outputs: bit for bit scipy's '2-point' J
                jc[:, i] = ((out - self.y[start:stop]) - r) / steps[i]
            total += float(r @ r)
            jtj += jc.T @ jc
            jtr += jc.T @ r
        if not (np.isfinite(total) and np.all(np.isfinite(jtj))):
            return _rejected(p)
        return NormalEquations(0.5 * total, jtj, jtr)


def _rejected(p: int) -> NormalEquations:
    """A point whose run is not finite: infinite cost, which the solver rejects."""
    return NormalEquations(np.inf, np.full((p, p), np.nan), np.full(p, np.nan))
