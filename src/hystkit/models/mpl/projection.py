"""The mPL cost with its linear parameters projected out (variable projection): the search of
a 1-cell fit (:func:`hystkit.models.mpl.fit.fit_mpl`, issue 29.5) moves the cells' shapes only,
with the best weights at every point."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...identification import NormalEquations

__all__ = ["CANCELLATION", "COST_SCALE", "Projection"]

# The projected cost is handed to the solver multiplied by this constant: the same minimum and
# the same steps (up to rounding), but the solver's gradient test, absolute (gtol 1e-8 on the
# scaled gradient, as scipy's), no longer stops a near-exact fit short of its optimum: on
# noise-free data at the Euler cap (tests/models/mpl/test_mpl_limits.py) the full search ends
# at SSE 8.6e-20, the projected one at 1.6e-9 unscaled, 1.7e-19 at 1e10 and 1.7e-21 at 1e12.
# On the benchmark's and real data (SSE >> 1e-12) ftol stops it first, in the same runs.
COST_SCALE = 1e12
# A projected cost below this share of the probe's cost (the pass at w = (0, 1, ..., 1),
# V_b = 0) is computed again from a pass at its own weights: the difference of the two loses
# about log10(1 / share) of the 16 digits, and ftol (1e-8) needs the rest.
CANCELLATION = 1e-6


def _bounded_linear(q: np.ndarray, g: np.ndarray, low: np.ndarray,
                    high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``d`` minimising ``d^T q d + 2 g^T d`` within ``low <= d <= high``, and which of its
    coordinates are free (inside their bounds): an active set grown until no free coordinate
    leaves its box (the mPL weights reach their box only on hard data, one or two of them)."""
    d, free = np.zeros(g.size), np.ones(g.size, bool)
    while free.any():
        d[free] = -np.linalg.lstsq(q[np.ix_(free, free)], g[free] + q[np.ix_(free, ~free)]
                                   @ d[~free], rcond=None)[0]
        out = free & ((d < low) | (d > high))
        if not out.any():
            break
        d, free = np.clip(d, low, high), free & ~out
    return d, free


class Projection:
    """The mPL cost with its linear parameters (``w``, ``V_b``) projected out (variable
    projection, Golub and Pereyra 1973): a function of the cells' ``(log G, log V_T)`` alone,
    called like a ``normal_equations`` callable of
    :func:`hystkit.identification.fit_multistart`.

    The output ``w_0 u + sum_k w_k x_k - V_b`` is linear in them and each state ``x_k`` depends
    on its own cell only, so one pass at ``w = (0, 1, ..., 1)``, ``V_b = 0`` gives everything:
    the best linear parameters in their box (a small quadratic problem), the cost there, and
    the cells' Jacobian there (their columns scaled by ``w_k``). The reduced normal equations are
    Kaufman's: ``J_n^T (I - P) J_n`` over the free linear parameters, gradient ``J_n^T r``, all
    times ``COST_SCALE``; a near-exact fit gets a second pass at its own weights
    (``CANCELLATION``). A search then moves the cell shapes only, its weights always the best
    for them.

    Parameters
    ----------
    normal_equations : callable
        ``theta -> NormalEquations`` of the full problem (optimiser coordinates of
        ``MplParams.to_vector``).
    n_cells : int
        Number of cells.
    lin_lower, lin_upper : numpy.ndarray, shape (n_cells + 2,)
        The box of ``w_0 .. w_N, V_b``.
    """

    def __init__(self, normal_equations: Callable[[np.ndarray], NormalEquations], n_cells: int,
                 lin_lower: np.ndarray, lin_upper: np.ndarray) -> None:
        self._normal_equations = normal_equations
        self._n = n_cells
        self._low, self._high = lin_lower, lin_upper
        self._unit = np.r_[0.0, np.ones(n_cells), 0.0]
        self._linear: dict[bytes, np.ndarray] = {}

    def __call__(self, cells: np.ndarray) -> NormalEquations:
        cost, hess, grad, linear, probe_cost = self._project(cells, self._unit)
        if cost < CANCELLATION * probe_cost and np.all(linear[1: self._n + 1] != 0):
            # a near-exact fit: its cost, found as the probe's minus the projection, has lost
            # its digits; a pass at the best weights gives it (and its derivatives) again
            cost, hess, grad, linear, _ = self._project(cells, linear)
        self._linear[cells.tobytes()] = linear
        return NormalEquations(COST_SCALE * cost, COST_SCALE * hess, COST_SCALE * grad)

    def _project(self, cells: np.ndarray, probe: np.ndarray) -> tuple:
        """``(cost, J^T J, J^T r, best weights, probe's cost)`` of the projected problem from
        one pass at weights `probe` (the cells' weights nonzero)."""
        m = 2 * self._n
        ne = self._normal_equations(np.concatenate((cells, probe)))
        if not np.isfinite(ne.cost):
            return ne.cost, ne.jtj[:m, :m], ne.jtr[:m], probe, ne.cost
        jtj, jtr = ne.jtj, ne.jtr
        q, cross = jtj[m:, m:], jtj[:m, m:]
        low, high = self._low - probe, self._high - probe
        # one solve for the weights and the projection when no weight is on its box
        rhs = np.concatenate((jtr[m:, None], cross.T), axis=1)
        try:
            solved = np.linalg.solve(q, rhs)
        except np.linalg.LinAlgError:  # collinear states (e.g. a cell that does not move)
            solved = np.linalg.lstsq(q, rhs, rcond=None)[0]
        d = -solved[:, 0]
        if np.all((d >= low) & (d <= high)):
            hess = jtj[:m, :m] - cross @ solved[:, 1:]
        else:
            d, free = _bounded_linear(q, jtr[m:], low, high)
            kept = cross[:, free]
            hess = jtj[:m, :m] - kept @ np.linalg.lstsq(q[np.ix_(free, free)], kept.T,
                                                        rcond=None)[0]
        linear = probe + d
        scale = np.repeat(linear[1: self._n + 1] / probe[1: self._n + 1], 2)
        grad = scale * (jtr[:m] + cross @ d)
        hess = scale[:, None] * (0.5 * (hess + hess.T)) * scale[None, :]
        return ne.cost + jtr[m:] @ d + 0.5 * d @ q @ d, hess, grad, linear, ne.cost

    def full(self, cells: np.ndarray) -> np.ndarray:
        """The whole optimiser vector at `cells`: with its best linear parameters."""
        key = np.asarray(cells, float).tobytes()
        if key not in self._linear:  # a point a worker evaluated: run once more here
            self(np.asarray(cells, float))
        return np.r_[cells, self._linear[key]]

    @staticmethod
    def no_residual(theta: np.ndarray) -> np.ndarray:
        raise NotImplementedError("the projected cost has normal equations only")
