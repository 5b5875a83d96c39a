"""Where the polynomial mPL model rests: the cells' equilibria and rest voltages, the check
that a stable rest exists, the output bound, the monotone branches of the output resistor that
the inverse runs on, and the rest state of a run.
"""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._docs import docfiller
from . import kernels
from .records import (
    REST_MAX,
    MplPolyParams,
    MplPolyStructure,
)
from .resistors import (
    _cubic,
    knee_points,
    output_slope,
    resistor_slope,
)

fill_doc = docfiller("MplPolyStructure", "MplPolyParams")


@fill_doc
def equilibria(structure: MplPolyStructure, params: MplPolyParams) -> list[np.ndarray]:
    """Every rest voltage ``v*`` with ``f_k,lim(v*) = 0`` of each cell, ascending.

    At rest ``u_k = e - v*``: the rest voltage does not depend on the input.

    %(records_parameters)s

    Returns
    -------
    list of numpy.ndarray
        Per cell, its rest voltages ``v*``, ascending.
    """
    knees = knee_points(structure, params)
    s = structure.slope_cap / structure.dt
    out = []
    for k, c in enumerate(params.f):
        roots = np.roots(c[::-1])
        v = roots[np.abs(roots.imag) <= 1e-9 * (1 + np.abs(roots))].real
        if structure.limit:
            xm, xp = knees[k]
            v = list(v[(v > xm) & (v < xp)])
            f_m, f_p = _cubic(c, np.array([xm, xp]))[0]
            # roots on the straight continuations (the two coincide in a one-line cell)
            v += [xp - f_p / s] if f_p <= 0 else []
            v += [xm - f_m / s] if f_m >= 0 else []
        out.append(np.unique(np.asarray(v, dtype=float)))
    return out


@fill_doc
def check_rest(structure: MplPolyStructure, params: MplPolyParams) -> None:
    """Raise FitDivergedError unless every rest voltage of the limited resistors at this
    ``dt`` (:func:`equilibria`) lies within ``REST_MAX``: the straight continuations can move
    a cell's rest point far beyond its cubic's roots (a steep cubic, a small ``slope_cap``).

    %(records_parameters)s

    Raises
    ------
    FitDivergedError
        A rest voltage beyond ``REST_MAX``, naming the cell.
    """
    for k, v in enumerate(equilibria(structure, params)):
        if v.size and np.max(np.abs(v)) > REST_MAX:
            raise FitDivergedError(
                f"cell {k + 1} of the mpl-poly model rests at v = {v[np.argmax(np.abs(v))]:.4g} "
                f"with dt = {structure.dt:g}, slope_cap = {structure.slope_cap:g}: outside the "
                f"domain |v| <= {REST_MAX:g} where runs stay bounded")


@fill_doc
def output_bound(structure: MplPolyStructure, params: MplPolyParams, u_max: float) -> float:
    """Largest ``|y|`` of a forward run from rest with ``|u| <= u_max`` and
    ``slope_cap <= 1``.

    Each Euler step keeps ``u_k`` between its previous value and ``e - v*`` for the rest
    voltages ``v*`` of the limited resistor (its slope never exceeds ``slope_cap / dt``), so
    ``|u_k| <= u_max + R_k`` with ``R_k`` the largest ``|v*|``; then
    ``|z| <= |w_0| u_max + sum |w_k| (u_max + R_k) + |V_b|`` and
    ``|y| <= sum_j |g_j| |z|^j``.

    Parameters
    ----------
    %(structure)s
    %(u_max)s

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    r = np.array([np.max(np.abs(v), initial=0.0) for v in equilibria(structure, params)])
    z = abs(params.w[0]) * u_max + np.abs(params.w[1:]) @ (u_max + r) + abs(params.v_b)
    return float(np.abs(params.g) @ z ** np.arange(4))


@fill_doc
def rest_voltages(structure: MplPolyStructure, params: MplPolyParams) -> np.ndarray:
    """Default start: each cell at a stable rest voltage (``f' > 0``), shape (N,).

    A cubic with ``c3 > 0`` always has one (its largest root). When there are two (a bistable
    cell) the one nearer the cubic's inflection point ``-c2 / (3 c3)`` is taken (the lower on a
    tie): unlike "nearest to 0" this does not depend on how the cell voltage is offset, so
    equivalent parameters (``fit.canonical``) start in the same state.

    %(records_parameters)s

    Returns
    -------
    numpy.ndarray, shape (N,)
        One stable rest voltage ``v*`` per cell.
    """
    out = np.empty(params.n_cells)
    centre = -params.f[:, 2] / (3 * params.f[:, 3])
    for k, v in enumerate(equilibria(structure, params)):
        probe = np.zeros((v.size, params.n_cells))
        probe[:, k] = v
        slope = resistor_slope(structure, params, probe)[:, k]
        stable = v[slope > 0] if np.any(slope > 0) else v
        out[k] = stable[np.argmin(np.abs(stable - centre[k]))]
    return out


@fill_doc
def output_branch(structure: MplPolyStructure,
                  params: MplPolyParams) -> tuple[float, float, float]:
    """The monotone branch of ``g`` used by :func:`invert`: ``(lo, hi, sign)``.

    The branch contains ``z_rest = -sum w_k v*_k - V_b``, the output resistor's voltage when
    the model rests at ``e = 0`` (the centre of centred, normalised data); it is the largest
    interval around it where ``g'`` keeps its sign (bounds at the roots of ``g'``, ``+-inf``
    where there are none). Defined this way it is the same branch for all equivalent parameters
    (``fit.canonical``).

    %(records_parameters)s

    Returns
    -------
    %(branch)s

    %(no_branch)s
    """
    z_rest = -params.w[1:] @ rest_voltages(structure, params) - params.v_b
    return branch_around(params, z_rest)


def branch_around(params: MplPolyParams, z_rest: float) -> tuple[float, float, float]:
    """``(lo, hi, sign)``: the monotone branch of the cubic ``g`` through ``z_rest`` (between
    the nearest real roots of ``g'``, ``+-inf`` where there is none) and the sign of ``g'`` on
    it; shared with the ch. 7 compensator (``mpl_g``), whose ``g`` is the same cubic.

    Parameters
    ----------
    params : MplPolyParams or MplGParams
        Parameters with the output resistor's coefficients ``g``.
    z_rest : float
        The operating point.

    Returns
    -------
    lo, hi, sign : float
        As :func:`output_branch`.

    Raises
    ------
    FitDivergedError
        If ``g'(z_rest) = 0``.
    """
    slope = float(output_slope(params, z_rest))
    if slope == 0:
        raise FitDivergedError(f"the output resistor has g'(z) = 0 at the rest point "
                               f"z = {z_rest:.4g}, so it is not invertible there")
    roots = np.roots([3 * params.g[3], 2 * params.g[2], params.g[1]])
    roots = roots[np.abs(roots.imag) <= 1e-12 * np.abs(roots)].real
    lo = max(roots[roots < z_rest], default=-np.inf)
    hi = min(roots[roots > z_rest], default=np.inf)
    return float(lo), float(hi), float(np.sign(slope))



@fill_doc
def inverse_branch(structure: MplPolyStructure,
                   params: MplPolyParams) -> tuple[float, float, float, float]:
    """``(lo, hi, sign, centre)``: :func:`output_branch` and the rest point ``z_rest`` inside it,
    where the inverse's Newton search starts widening its bracket (the arguments of
    ``kernels.solve_output``). Raises as :func:`output_branch`.

    %(records_parameters)s

    Returns
    -------
    %(branch)s
    centre : float
        ``z_rest``.

    Raises
    ------
    FitDivergedError
        As :func:`output_branch`.
    """
    lo, hi, sign = output_branch(structure, params)
    centre = -params.w[1:] @ rest_voltages(structure, params) - params.v_b
    return lo, hi, sign, float(centre)


def solve_on_branch(structure: MplPolyStructure, params: MplPolyParams,
                    y: float) -> tuple[float, bool]:
    """``(z, ok)``: the ``z`` on :func:`inverse_branch` with ``g(z) = y``, as the compiled
    inverse finds it (``kernels.solve_output``); ``ok`` false outside the branch's range."""
    return kernels.solve_output(float(y), np.ascontiguousarray(params.g),
                                *inverse_branch(structure, params))


@fill_doc
def rest_state(structure: MplPolyStructure, params: MplPolyParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Cells at rest, ``u_k = e - v*_k`` (:func:`rest_voltages`), shape (N,).

    Forward: ``e`` is the constant input ``value``. Inverse (``value`` a constant output):
    ``e_0 = (z_0 + sum w_k v*_k + V_b) / sum w`` with ``g(z_0) = value`` on the branch, the
    input at which the model rests with that output; ``e_0 = 0`` if ``value`` is outside the
    branch's range or ``sum w = 0``. :func:`simulate` / :func:`invert` start here for
    ``x0=None``.

    %(rest_state)s
    """
    v_rest = rest_voltages(structure, params)
    if not inverse:
        return float(value) - v_rest
    z0, ok = solve_on_branch(structure, params, value)
    w_sum = params.w.sum()
    e0 = (z0 + params.w[1:] @ v_rest + params.v_b) / w_sum if ok and w_sum != 0 else 0.0
    return e0 - v_rest


def check_branch_inverse(why: int, n_bad: int, y: np.ndarray, lo: float, hi: float) -> None:
    """Raise FitDivergedError for a failed run of a branch inverse kernel (mpl-poly, mpl-g):
    ``why`` 1, a sample outside the range ``[lo, hi]`` of the output resistor's monotone
    branch; 2, the estimate diverged; 0, no failure.

    Parameters
    ----------
    why : int
        The kernel's failure code.
    n_bad : int
        The sample it failed at.
    y : numpy.ndarray
        The output inverted.
    lo, hi : float
        The range of the monotone branch.
    """
    if why == 1:
        raise FitDivergedError(
            f"the inverse failed at sample {n_bad} of {y.size}: output {y[n_bad]:.4g} is outside "
            f"the range of the output resistor g on its monotone branch [{lo:.4g}, {hi:.4g}]")
    if why == 2:
        raise FitDivergedError(
            f"the inverse model diverged at sample {n_bad} of {y.size} (|e_hat| > 1e6 times the "
            f"output range); the fitted weights make the compensator unstable on this data")
