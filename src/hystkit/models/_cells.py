"""Linearisation and discrete stability of the mPL families (sec. 5.3.5, eq. 5.18-5.28).

For cells ``du_k/dt = f_k(e - u_k)`` and output ``i = g(z)``, ``z = w_0 e + sum w_k u_k - V_b``,
the first-order Taylor expansion about an operating point ``(e_0, u_0)`` is, with the state
augmented by a constant 1 (eq. 5.22) and in *absolute* coordinates::

    du_k/dt = -f'_k u_k + f'_k e + o_k,   o_k = f_k(v_k0) - f'_k v_k0,   v_k0 = e_0 - u_k0
    i       = g'_0 (w_0 e + sum w_k u_k) + g_0 - g'_0 (z_0 + V_b)

with ``f_k, f'_k`` evaluated at ``v_k0 = e_0 - u_k0``. Corrections to the document:

- eq. 5.19 evaluates ``f_k(u_k0 - e_0)``; the cell's argument is ``e - u`` (eq. 5.17), so it is
  ``f_k(e_0 - u_k0)``.
- eq. 5.18/5.23 use ``f_k0`` as the constant column and ``g_0 - g'_0 V_b`` as the output
  constant; that is right only for ``e_0 = u_0 = 0``. The affine terms above are exact for any
  operating point (the linear model reproduces the step at the point itself).
- eq. 5.26 prints ``lambda = (1 - f'_k) dt``. Forward Euler gives ``A_d = I + A dt``, which is
  upper triangular, so its eigenvalues are its diagonal: ``1 - f'_k dt`` for the cells and
  **1** for the augmented constant state (its continuous eigenvalue is 0; it is a constant, not
  a mode, and is left out of the stability test). The condition ``|1 - f'_k dt| < 1`` gives
  eq. 5.28, ``0 < f'_k dt < 2``.

Both the sinh mPL (``mpl``, linear output ``g(z) = z``) and the polynomial mPL (``mpl_poly``)
describe themselves as :class:`Cells` (their families' ``cells`` method); everything here works
on that description and imports no family.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import FitDivergedError
from ._protocol import Record, Reduction
from ._validation import check_cells, check_range, check_size, check_structure_size

__all__ = ["DT_RANGE", "MAX_CELLS", "MAX_MERGED_CELLS", "SLOPE_CAP_MIN", "CellStructure", "Cells",
           "LimitedCellStructure", "LinearModel", "cell_reductions", "cell_report",
           "check_weighted_cells", "discrete_eigenvalues", "linearise", "linearise_cells",
           "state_bound"]

# Limits shared by the cell models (mpl, mpl-poly, pl, ladder). Runs cost O(N) a sample and
# fits hold an (n_samples x ~3N) Jacobian, so 1000 cells (24 kB of parameters, 24 MB of
# Jacobian per 1000 samples) is far beyond any useful model yet nowhere near a hang.
MAX_CELLS = 1000
# Sample times outside 1 ns .. 11.6 days are not recordings; inside, slope_cap / dt and
# V_T / dt stay far from the float range whatever else the parameters are.
DT_RANGE = (1e-9, 1e6)
# A slope cap below 1e-6 moves a capped cell by less than a millionth of its gap per sample,
# and the straight continuations' rest points (f(knee) / cap) run off to 1e300.
SLOPE_CAP_MIN = 1e-6
# Merging every ordered pair of cells costs N (N - 1) model runs: beyond this many cells
# only dropping each one is tried (N runs).
MAX_MERGED_CELLS = 10


def state_bound(x0_max: float, u_max: float, slope_cap: float) -> float:
    """Largest ``|u_k|`` a cell ``x+ = x + f(e - x) dt`` can reach from ``|x0| <= x0_max``
    under inputs ``|e| <= u_max``, when ``f`` is increasing through ``f(0) = 0`` with secant
    slope ``f(v) / v <= slope_cap / dt``.

    Each step moves ``x`` towards ``e``; it overshoots by at most ``(slope_cap - 1) |x - e|``,
    so ``|x+| <= max(|x|, u_max, u_max + (slope_cap - 1)(|x| + u_max))``, whose fixed point is
    ``u_max slope_cap / (2 - slope_cap)``. With ``slope_cap <= 1`` it is ``max(x0_max, u_max)``.
    """
    return max(x0_max, u_max * max(1.0, slope_cap / (2.0 - slope_cap)))


@dataclass(frozen=True)
class CellStructure(Record):
    """What does not get fitted in a model of RC cells: cell count, sample time, Euler slope cap.

    Parameters
    ----------
    n_cells : int
        Number of cells ``N`` (>= 1).
    dt : float
        Sample time of the recordings the model runs on [s].
    slope_cap : float
        Largest allowed Euler slope ``f' dt`` (eq. 5.28 requires < 2; 1 gives overshoot-free
        cells).

    Limits: ``1 <= n_cells <= MAX_CELLS`` (1000, checked first, before anything is allocated),
    ``dt`` in ``DT_RANGE`` (1e-9 .. 1e6 s) and ``slope_cap >= SLOPE_CAP_MIN`` (1e-6).
    """

    n_cells: int = 1
    dt: float = 0.025
    slope_cap: float = 1.0

    def __post_init__(self) -> None:
        check_structure_size(self.n_cells, "n_cells", MAX_CELLS)
        check_cells(self.n_cells, self.dt, self.slope_cap)
        check_range(self.dt, "dt", *DT_RANGE, " s")
        check_range(self.slope_cap, "slope_cap", SLOPE_CAP_MIN, 2.0, " (below 2: eq. 5.28)")


@dataclass(frozen=True)
class LimitedCellStructure(CellStructure):
    """A :class:`CellStructure` with the switch of the stability limit (eq. 5.29): ``limit``
    (bool, default True) applies it; ``False`` runs the raw cell resistor, which may diverge.
    """

    limit: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        if not isinstance(self.limit, bool):
            raise TypeError(f"limit must be true or false, got {self.limit!r}")


def check_weighted_cells(structure: CellStructure, params: Record, inverse: bool) -> None:
    """The check before a run of an mPL family (``Runs.check``): the parameters have as many
    cells as the structure, and the inverse needs ``w_0 != 0`` (eq. 5.13)."""
    check_size(params.n_cells, structure.n_cells, "cells")
    if inverse and params.w[0] == 0:
        raise FitDivergedError("the model has w_0 = 0, so it has no inverse (eq. 5.13)")


@dataclass(frozen=True, eq=False)
class Cells:
    """An RC-cell model as the analysis of eq. 5.18-5.28 sees it.

    Attributes
    ----------
    current, slope : callable
        ``v (..., N) -> f_k,lim(v_k)`` and ``-> f'_k,lim(v_k)``: the limited cell resistors.
    output, output_slope : callable
        ``z -> g(z)`` and ``-> g'(z)`` (the sinh mPL: ``z`` and 1).
    w : array, shape (N + 1,)
    v_b : float
    dt : float
    knees : array, shape (N, 2)
        ``x-, x+`` of each cell beyond which ``f'_k dt`` is capped.
    rest_points : list of arrays
        Per cell, the voltages where ``f_k = 0``.
    start : callable
        ``e_0 -> u (N,)``: the state the model starts in for a first input ``e_0``.
    check : callable
        ``u -> None``: runs the model on ``u``; raises FitDivergedError if it diverges.
    """

    current: Callable[[np.ndarray], np.ndarray]
    slope: Callable[[np.ndarray], np.ndarray]
    output: Callable[[float], float]
    output_slope: Callable[[float], float]
    w: np.ndarray
    v_b: float
    dt: float
    knees: np.ndarray
    rest_points: list
    start: Callable[[float], np.ndarray]
    check: Callable[[np.ndarray], None]

    @property
    def n_cells(self) -> int:
        return int(np.size(self.w)) - 1


@dataclass(frozen=True, eq=False)
class LinearModel:
    """Augmented linear state space (eq. 5.23) of one operating point; state ``[u_1..u_N, 1]``.

    Attributes
    ----------
    a : array, shape (N + 1, N + 1)
    b : array, shape (N + 1,)
    c : array, shape (N + 1,)
    d : float
    dt : float
        Euler step [s] for :meth:`discrete`.
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: float
    dt: float

    def discrete(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Forward-Euler discretisation (eq. 5.24, paper eq. 7): ``A_d = I + A dt``,
        ``B_d = B dt``, ``C_d = C``, ``D_d = D``."""
        return (np.eye(self.a.shape[0]) + self.a * self.dt, self.b * self.dt, self.c.copy(),
                self.d)


def linearise_cells(current: Callable[[np.ndarray], np.ndarray],
                    slope: Callable[[np.ndarray], np.ndarray],
                    output: Callable[[float], float], output_slope: Callable[[float], float],
                    w: np.ndarray, v_b: float, e0: float, u0: np.ndarray,
                    dt: float) -> LinearModel:
    """Linearise cells ``du_k/dt = f_k(e - u_k)`` with output ``g(z)`` (eq. 5.18-5.23).

    Parameters
    ----------
    current, slope : callable
        ``v (N,) -> f_k(v_k) (N,)`` and ``-> f'_k(v_k) (N,)``: the (limited) cell resistors.
    output, output_slope : callable
        ``z -> g(z)`` and ``-> g'(z)``.
    w : array, shape (N + 1,)
    v_b : float
    e0 : float
        Input at the operating point.
    u0 : array, shape (N,)
        Cell voltages at the operating point.
    dt : float
        Sample time [s].
    """
    u0 = np.asarray(u0, dtype=float)
    n = u0.size
    v0 = e0 - u0
    f0, df0 = np.asarray(current(v0), dtype=float), np.asarray(slope(v0), dtype=float)
    z0 = w[0] * e0 + w[1:] @ u0 - v_b
    g0, dg0 = float(output(z0)), float(output_slope(z0))
    a = np.zeros((n + 1, n + 1))
    a[:n, :n] = np.diag(-df0)
    a[:n, n] = f0 - df0 * v0
    c = np.r_[dg0 * w[1:], g0 - dg0 * (z0 + v_b)]
    return LinearModel(a=a, b=np.r_[df0, 0.0], c=c, d=dg0 * w[0], dt=dt)


def discrete_eigenvalues(model: LinearModel) -> np.ndarray:
    """Eigenvalues of ``A_d = I + A dt``, shape (N + 1,): ``1 - f'_k dt`` per cell, then 1.

    ``A_d`` is upper triangular (diagonal cells, constant column), so these are its diagonal.
    The last one belongs to the augmented constant state (see the module docstring).
    """
    return np.diag(model.discrete()[0]).copy()


def linearise(cells: Cells, e0: float, u0: np.ndarray) -> LinearModel:
    """Linear model (eq. 5.23) at input ``e0``, state ``u0`` (N,)."""
    return linearise_cells(cells.current, cells.slope, cells.output, cells.output_slope,
                           cells.w, cells.v_b, e0, u0, cells.dt)


def cell_report(cells: Cells, u: np.ndarray) -> dict:
    """Where the linearised model is stable (eq. 5.28): rest points and a driven trajectory.

    Operating points: every rest point of every cell (``f_k(v*) = 0``; ``u_k = e - v*`` for any
    ``e``, so the cells' eigenvalues at rest do not depend on the input), and every sample of
    the model run on ``u`` from its default start (the states the data actually visit).

    Parameters
    ----------
    u : array, shape (n,)
        Model input covering the training range (normalised data: about [-1, 1]).

    Returns
    -------
    dict
        Plain JSON: ``dt``, ``n_cells``, ``knees`` (N x [x-, x+]), ``rest`` (per cell: rest
        voltages, ``f' dt`` and eigenvalues there), ``trajectory`` (sample count and per cell
        the range of ``f' dt`` and of the eigenvalues), ``eigenvalue_min/max`` over all
        points, ``n_points``, ``n_violations`` (points with ``f' dt`` outside (0, 2)) and
        ``stable_everywhere``; the augmented constant state (eigenvalue 1) is not counted.
    """
    u = np.asarray(u, dtype=float)
    dt, n = cells.dt, cells.n_cells
    rest = []
    slopes_rest = []
    for k, v in enumerate(cells.rest_points):
        probe = np.zeros((v.size, n))
        probe[:, k] = v
        s = cells.slope(probe)[:, k] * dt
        slopes_rest.append(s)
        rest.append({"v": v.tolist(), "slope_dt": s.tolist(), "eigenvalue": (1 - s).tolist()})
    cells.check(u)  # FitDivergedError if the run diverges (no limit)
    x = cells.start(float(u[0]))
    states = np.empty((u.size, n))
    for i, u_i in enumerate(u):  # the states the run visits (an analysis, not a hot path)
        states[i] = x
        x = x + cells.current(u_i - x) * dt
    slopes_traj = cells.slope(u[:, None] - states) * dt
    everything = np.concatenate([np.concatenate(slopes_rest), slopes_traj.ravel()])
    bad = (everything <= 0) | (everything >= 2)
    return {
        "dt": dt, "n_cells": n, "knees": np.asarray(cells.knees).tolist(), "rest": rest,
        "trajectory": {"n_samples": int(u.size),
                       "slope_dt_min": slopes_traj.min(axis=0).tolist(),
                       "slope_dt_max": slopes_traj.max(axis=0).tolist(),
                       "eigenvalue_min": (1 - slopes_traj.max(axis=0)).tolist(),
                       "eigenvalue_max": (1 - slopes_traj.min(axis=0)).tolist()},
        "eigenvalue_min": float(1 - everything.max()),
        "eigenvalue_max": float(1 - everything.min()),
        "n_points": int(everything.size), "n_violations": int(bad.sum()),
        "stable_everywhere": bool(not bad.any()),
    }


def cell_reductions(structure: CellStructure, params: Record) -> tuple[Reduction, ...]:
    """The models of ``N - 1`` cells made from a fitted cell model without refitting.

    For parameters with per-cell ``i_s``, ``v_t`` (N,) and weights ``w`` (N + 1,; ``w[0]`` the
    feed-through, ``w[k]`` cell k's), other fields kept: each cell dropped with its weight,
    and (up to ``MAX_MERGED_CELLS`` cells) each cell merged into each other one (dropped, its
    weight added to the other's). The merge is exact when the two cells have the same resistor
    (equal voltages for all time): a fit can then split one weight into two large ones of
    opposite sign of which only the sum is determined (-14.6 and +12.8 for -1.8).

    Parameters
    ----------
    structure : CellStructure
        The fitted model's structure (``n_cells`` N).
    params : Record
        Its parameters.

    Returns
    -------
    tuple of Reduction
        The drops first, then the merges; empty for one cell. Cells are numbered from 1, as
        ``w[k]``.
    """
    n = structure.n_cells
    if n < 2:
        return ()
    smaller = dataclasses.replace(structure, n_cells=n - 1)
    label = f"{n - 1} cell{'s' if n > 2 else ''}"
    w = np.asarray(params.w, dtype=float)

    def without(k: int, weights: np.ndarray) -> Record:
        keep = [i for i in range(1, n + 1) if i != k]
        cells = np.asarray(keep) - 1
        return dataclasses.replace(params, i_s=np.asarray(params.i_s)[cells],
                                   v_t=np.asarray(params.v_t)[cells],
                                   w=np.r_[weights[0], weights[keep]])

    drops = [Reduction(f"cell {k} adds nothing the data resolve (w[{k}] = {w[k]:.3g})",
                       n - 1, label, smaller, without(k, w)) for k in range(1, n + 1)]
    merges = []
    for k, j in itertools.permutations(range(1, n + 1) if n <= MAX_MERGED_CELLS else (), 2):
        merged = w.copy()
        merged[j] += w[k]
        a, b = sorted((j, k))
        kind = "cancel" if w[j] * w[k] < 0 else "duplicate each other"
        merges.append(Reduction(f"cells {a} and {b} {kind} (weights {w[a]:+.3g}, {w[b]:+.3g})",
                                n - 1, label, smaller, without(k, merged)))
    return (*drops, *merges)
