"""Polynomial modified Power-Law (mPL) model, sec. 5.3.5 and paper 9.2 of the reference document.

``N`` cells, each a capacitor ``C = 1`` charged through a cubic resistor ``f_k``; a cubic output
resistor ``g`` carries the output current (eq. 5.16-5.17)::

    du_k/dt = f_k(e - u_k),      i = g(w_0 e + sum_k w_k u_k - V_b),
    f_k(v) = c_k0 + c_k1 v + c_k2 v^2 + c_k3 v^3,   g(z) = g_0 + g_1 z + g_2 z^2 + g_3 z^3

integrated with forward Euler (eq. 5.6). The state ``x`` is the vector of cell voltages ``u_k``.

Decisions where the document is ambiguous or wrong, with the evidence, are in
docs/models/mpl_poly.md; in short:

- eq. 5.16's ``f2^2 x^2 + f3^3 x^3`` is the paper's parametrisation, not a typo. The model holds
  the plain cubic coefficients ``c``; ``presets.paper_9_2_params`` converts the paper's printed values (``c2 = f2^2``, ``c3 = f3^3``).
- Per-cell ``f_k`` (eq. 5.17's subscript): with one shared ``f`` all cells would be equal.
  ``5N + 6`` parameters, the paper's 11 for ``N = 1``; only ``4N + 4`` are identifiable.
- ``c_k3 > 0`` is required: only then is the cell stable for large ``|v|`` (paper 9.2, sec.
  II-C relies on it) and do the knees of eq. 5.29 exist on both sides (table II has it).
- Stability limit (eq. 5.29, corrected, ``limit=True``): ``f`` on ``x- <= x <= x+`` and lines of
  slope ``s = slope_cap / dt`` outside, ``f(x+) + s (x - x+)`` and ``f(x-) + s (x - x-)``, with
  ``x-, x+`` the extreme solutions of ``f'(x) = s`` (both at the vertex of ``f'`` if ``f' >= s``
  everywhere). Inside, ``f' <= 0`` is possible: such an equilibrium repels, the state settles
  at an outer stable root and stays bounded; three real roots make the cell bistable.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from ...errors import FitDivergedError
from .._cells import MAX_CELLS, CellStructure
from .._protocol import Record
from .._validation import (
    broadcast_state,
    check_finite_run,
    check_magnitude,
    check_range,
    check_signal,
    check_size,
    check_structure_size,
    finite_floats,
    frozen_shaped,
    run_steps,
)
from . import kernels

__all__ = [
    "C3_RANGE",
    "G_MIN",
    "POLY_MAX",
    "REST_MAX",
    "MplPolyParams",
    "MplPolyStructure",
    "check_rest",
    "equilibria",
    "inverse_branch",
    "invert",
    "invert_step",
    "knee_points",
    "output_bound",
    "output_branch",
    "output_current",
    "output_slope",
    "resistor_current",
    "resistor_slope",
    "rest_state",
    "rest_voltages",
    "simulate",
    "simulate_reference",
    "simulate_with_jacobian",
    "step",
]


# The documented parameter domain, normalised units (eq. 5.10). It holds the fit's box
# (|c| <= 1e3, c3 in [1e-6, 1e4]), its canonical forms and paper 9.2's sets (c3 down to 5e-7).
# REST_MAX bounds where a cell can rest: every cubic of the box has its roots within
# 1 + 1e3 / 1e-6 (Cauchy), so 2e9 refuses nothing the fit can return (a tighter limit changed
# fits: on the virtual sensor's noise run c3 drifts along a flat valley to its box floor, cell
# resting at -3.8e5, and the fit is reported on bounds) but does refuse the cubics beyond
# (c3 = 1e-10 beside c2 = 1 rests 1e10 away) whose outputs overflow.
POLY_MAX = 1e9
# c3 may be tiny (a near-linear cell; its roots are located through 1 / v where c_j / c3
# overflows); nonzero g_j at least 1e-200, as the output branch divides by g's leading one.
C3_RANGE = (1e-300, 1e9)
G_MIN = 1e-200
REST_MAX = 2e9


@dataclass(frozen=True)
class MplPolyStructure(CellStructure):
    """What does not get fitted: cell count, sample time, Euler slope cap (outside the knees;
    :class:`~hystkit.models._cells.CellStructure`) and the limit switch.

    Parameters
    ----------
    n_cells : int, default 1
        Number of cells ``N``.
    dt : float, default 0.025
        Sample time [s].
    slope_cap : float, default 1.0
        Largest Euler slope ``f' dt`` outside the knees.
    limit : bool
        Apply the stability limit eq. 5.29; ``False`` runs the raw cubic (may diverge).
    """

    limit: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        if not isinstance(self.limit, bool):
            raise TypeError(f"limit must be true or false, got {self.limit!r}")

    @property
    def n_params(self) -> int:
        """``5N + 6`` fitted parameters (11 for the paper's N = 1)."""
        return 5 * self.n_cells + 6


@dataclass(frozen=True, eq=False)
class MplPolyParams(Record):
    """Fitted quantities of a polynomial mPL model.

    Parameters
    ----------
    f : array, shape (N, 4)
        Cubic coefficients ``c0..c3`` of each cell resistor, ``c3 > 0`` (eq. 5.16).
    g : array, shape (4,)
        Cubic coefficients of the output resistor (eq. 5.16-5.17).
    w : array, shape (N + 1,)
        VCVS weights ``w_0 .. w_N``.
    v_b : float
        Bias voltage ``V_b``.

    Notes
    -----
    Domain (checked here): ``|c_k0..c_k2|, |g_j| <= POLY_MAX`` (1e9), ``c_k3`` in
    ``C3_RANGE`` (1e-300 .. 1e9), each ``g_j`` 0 or at least ``G_MIN`` (1e-200) in
    magnitude, ``|w_k|, |V_b| <= 1e6``, at most 1000 cells, and every real root of every
    cell's cubic within ``|v| <= REST_MAX`` (2e9). The limited resistor's rest
    voltages depend on ``dt`` too; runs check them (:func:`check_rest`). With them, a run
    with ``slope_cap <= 1`` stays within :func:`output_bound`.

    The optimiser sees ``[c_k0, c_k1, c_k2, log c_k3 (per cell), g_0..g_3, w_0..w_N, V_b]``.
    """

    f: np.ndarray
    g: np.ndarray
    w: np.ndarray
    v_b: float = 0.0
    n_cells: int = field(init=False)

    def __post_init__(self) -> None:
        if np.ndim(self.f) >= 1:  # the cell count first, before the values are copied
            check_structure_size(len(self.f), "the number of cells (rows of f)", MAX_CELLS)
        shape = np.shape(frozen_shaped(self.f, None, "f"))
        if len(shape) != 2 or shape[0] < 1 or shape[1] != 4:
            raise ValueError(f"f must have shape (N, 4), one row per cell, got {shape}")
        n = shape[0]
        object.__setattr__(self, "n_cells", int(n))
        object.__setattr__(self, "f", frozen_shaped(self.f, (n, 4), "f"))
        object.__setattr__(self, "g", frozen_shaped(self.g, (4,), "g"))
        object.__setattr__(self, "w", frozen_shaped(self.w, (n + 1,), "w"))
        finite_floats(self, "v_b")
        check_range(self.f[:, 3], "the cubic coefficient f[k][3]", *C3_RANGE,
                    " (positive: stable for large |v|, sec. 5.3.5)")
        check_magnitude(self.f[:, :3], "f (c0..c2)", POLY_MAX)
        check_magnitude(self.g, "g", POLY_MAX)
        tiny = (self.g != 0) & (np.abs(self.g) < G_MIN)
        if np.any(tiny):
            raise ValueError(f"g must be 0 or at least {G_MIN:g} in magnitude (its roots are "
                             f"solved for), got {float(self.g[np.argmax(tiny)])!r}")
        check_magnitude(self.w, "w")
        check_magnitude(self.v_b, "v_b")
        for k, c in enumerate(self.f):
            far = _far_root(c)
            if far is not None:
                raise ValueError(f"f[{k}] (cell {k + 1}'s resistor) has a rest voltage at "
                                 f"{far:.4g}, outside the domain [-{REST_MAX:g}, {REST_MAX:g}] "
                                 f"(normalised units)")

    def to_vector(self) -> np.ndarray:
        """Optimiser coordinates (see Notes of the class)."""
        cells = np.column_stack([self.f[:, :3], np.log(self.f[:, 3])]).reshape(-1)
        return np.concatenate([cells, self.g, self.w, [self.v_b]])

    @classmethod
    def from_vector(cls, theta: np.ndarray, n_cells: int) -> MplPolyParams:
        """Inverse of :meth:`to_vector`."""
        theta = np.asarray(theta, dtype=float)
        cells = theta[: 4 * n_cells].reshape(n_cells, 4)
        f = np.column_stack([cells[:, :3], np.exp(cells[:, 3])])
        rest = theta[4 * n_cells:]
        return cls(f=f, g=rest[:4], w=rest[4: n_cells + 5], v_b=rest[n_cells + 5])


def _far_root(c: np.ndarray) -> float | None:
    """A real root of the cubic ``c`` (``c0..c3``) beyond ``REST_MAX``, or None.

    Roots of ``f`` beyond ``R`` are the roots ``t = 1 / v`` in ``0 < |t| < 1 / R`` of the
    reversed polynomial ``c3 + c2 t + c1 t^2 + c0 t^3``; that form is used when ``c_j / c3``
    overflows (a tiny ``c3``), the direct one otherwise.
    """
    with np.errstate(all="ignore"):
        for coef, reverse in ((c[::-1], False), (c, True)):
            try:
                roots = np.roots(coef)
            except np.linalg.LinAlgError:  # inf in the companion matrix
                continue
            if not np.all(np.isfinite(roots)):
                continue
            real = roots[np.abs(roots.imag) <= 1e-9 * (1 + np.abs(roots))].real
            if reverse:
                real = 1.0 / real[(real != 0) & (np.abs(real) < 1.0 / REST_MAX)]
            far = real[np.abs(real) > REST_MAX]
            return float(far[np.argmax(np.abs(far))]) if far.size else None
    return float("inf")  # no finite root computation: refuse rather than guess


def knee_points(structure: MplPolyStructure, params: MplPolyParams) -> np.ndarray:
    """Knees ``x-, x+`` of each cell, shape (N, 2): the extreme solutions of ``f'(x) = s``.

    ``s = slope_cap / dt``. With ``c3 > 0`` ``f'`` is an upward parabola, so ``f' > s`` exactly
    outside the knees; when it never drops to ``s`` both knees sit at its vertex.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.

    Returns
    -------
    numpy.ndarray, shape (N, 2)
        ``x-, x+`` per cell.
    """
    s = structure.slope_cap / structure.dt
    c1, c2, c3 = params.f[:, 1], params.f[:, 2], params.f[:, 3]
    vertex = -c2 / (3 * c3)
    half_width = np.sqrt(np.maximum(c2 * c2 - 3 * c3 * (c1 - s), 0.0)) / (3 * c3)
    return np.column_stack([vertex - half_width, vertex + half_width])


def _cubic(c: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return (c[..., 0] + x * (c[..., 1] + x * (c[..., 2] + x * c[..., 3])),
            c[..., 1] + x * (2 * c[..., 2] + 3 * c[..., 3] * x))


def _resistor(structure: MplPolyStructure, params: MplPolyParams,
              v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(v, dtype=float)
    f, df = _cubic(params.f, v)
    if not structure.limit:
        return f, df
    knees = knee_points(structure, params)
    s = structure.slope_cap / structure.dt
    x_b = np.where(v >= knees[:, 1], knees[:, 1], knees[:, 0])
    outside = (v >= knees[:, 1]) | (v <= knees[:, 0])
    return (np.where(outside, _cubic(params.f, x_b)[0] + s * (v - x_b), f),
            np.where(outside, s, df))


def resistor_current(structure: MplPolyStructure, params: MplPolyParams,
                     v: np.ndarray) -> np.ndarray:
    """Cell currents ``f_k,lim(v)`` (eq. 5.16 with 5.29 when ``structure.limit``).

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    v : array, shape (..., N)
        Voltage across each cell's resistor.

    Returns
    -------
    numpy.ndarray, shape (..., N)
        The cell currents.
    """
    return _resistor(structure, params, v)[0]


def resistor_slope(structure: MplPolyStructure, params: MplPolyParams,
                   v: np.ndarray) -> np.ndarray:
    """Slopes ``f'_k,lim(v)``, shape (..., N): the cells' rates in eq. 5.20 and 5.26.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    v : numpy.ndarray, shape (..., N)
        Voltage across each cell's resistor.

    Returns
    -------
    numpy.ndarray, shape (..., N)
        The slopes.
    """
    return _resistor(structure, params, v)[1]


def output_current(params: MplPolyParams, z: np.ndarray) -> np.ndarray:
    """Output resistor current ``g(z)`` (eq. 5.17).

    Parameters
    ----------
    params : MplPolyParams
        The model's parameters.
    z : numpy.ndarray
        Voltage across the output resistor.

    Returns
    -------
    numpy.ndarray
        ``g(z)``, same shape as `z`.
    """
    return _cubic(params.g, np.asarray(z, dtype=float))[0]


def output_slope(params: MplPolyParams, z: np.ndarray) -> np.ndarray:
    """Output resistor slope ``g'(z)`` (``g'_0`` of eq. 5.19).

    Parameters
    ----------
    params : MplPolyParams
        The model's parameters.
    z : numpy.ndarray
        Voltage across the output resistor.

    Returns
    -------
    numpy.ndarray
        ``g'(z)``, same shape as `z`.
    """
    return _cubic(params.g, np.asarray(z, dtype=float))[1]


def equilibria(structure: MplPolyStructure, params: MplPolyParams) -> list[np.ndarray]:
    """Every rest voltage ``v*`` with ``f_k,lim(v*) = 0`` of each cell, ascending.

    At rest ``u_k = e - v*``: the rest voltage does not depend on the input.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.

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


def check_rest(structure: MplPolyStructure, params: MplPolyParams) -> None:
    """Raise FitDivergedError unless every rest voltage of the limited resistors at this
    ``dt`` (:func:`equilibria`) lies within ``REST_MAX``: the straight continuations can move
    a cell's rest point far beyond its cubic's roots (a steep cubic, a small ``slope_cap``).

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.

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
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    u_max : float
        Largest input magnitude.

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    r = np.array([np.max(np.abs(v), initial=0.0) for v in equilibria(structure, params)])
    z = abs(params.w[0]) * u_max + np.abs(params.w[1:]) @ (u_max + r) + abs(params.v_b)
    return float(np.abs(params.g) @ z ** np.arange(4))


def rest_voltages(structure: MplPolyStructure, params: MplPolyParams) -> np.ndarray:
    """Default start: each cell at a stable rest voltage (``f' > 0``), shape (N,).

    A cubic with ``c3 > 0`` always has one (its largest root). When there are two (a bistable
    cell) the one nearer the cubic's inflection point ``-c2 / (3 c3)`` is taken (the lower on a
    tie): unlike "nearest to 0" this does not depend on how the cell voltage is offset, so
    equivalent parameters (``fit.canonical``) start in the same state.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.

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


def output_branch(structure: MplPolyStructure,
                  params: MplPolyParams) -> tuple[float, float, float]:
    """The monotone branch of ``g`` used by :func:`invert`: ``(lo, hi, sign)``.

    The branch contains ``z_rest = -sum w_k v*_k - V_b``, the output resistor's voltage when
    the model rests at ``e = 0`` (the centre of centred, normalised data); it is the largest
    interval around it where ``g'`` keeps its sign (bounds at the roots of ``g'``, ``+-inf``
    where there are none). Defined this way it is the same branch for all equivalent parameters
    (``fit.canonical``).

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.

    Returns
    -------
    lo, hi : float
        The branch's bounds (``+-inf`` where unbounded).
    sign : float
        Sign of ``g'`` on it.

    Raises
    ------
    FitDivergedError
        If ``g'(z_rest) = 0`` (no monotone branch through the operating point).
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



def inverse_branch(structure: MplPolyStructure,
                   params: MplPolyParams) -> tuple[float, float, float, float]:
    """``(lo, hi, sign, centre)``: :func:`output_branch` and the rest point ``z_rest`` inside it,
    where the inverse's Newton search starts widening its bracket (the arguments of
    ``kernels.solve_output``). Raises as :func:`output_branch`.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.

    Returns
    -------
    lo, hi : float
        The branch's bounds (``+-inf`` where unbounded).
    sign : float
        Sign of ``g'`` on it.
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


def rest_state(structure: MplPolyStructure, params: MplPolyParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Cells at rest, ``u_k = e - v*_k`` (:func:`rest_voltages`), shape (N,).

    Forward: ``e`` is the constant input ``value``. Inverse (``value`` a constant output):
    ``e_0 = (z_0 + sum w_k v*_k + V_b) / sum w`` with ``g(z_0) = value`` on the branch, the
    input at which the model rests with that output; ``e_0 = 0`` if ``value`` is outside the
    branch's range or ``sum w = 0``. :func:`simulate` / :func:`invert` start here for
    ``x0=None``.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    value : float
        Constant input (with `inverse`: output) the model rests at.
    inverse : bool, default False
        Rest state of the inverse: `value` is an output.

    Returns
    -------
    numpy.ndarray
        The state at rest.
    """
    v_rest = rest_voltages(structure, params)
    if not inverse:
        return float(value) - v_rest
    lo, hi, sign, centre = inverse_branch(structure, params)
    z0, ok = kernels.solve_output(float(value), np.ascontiguousarray(params.g), lo, hi, sign,
                                  centre)
    w_sum = params.w.sum()
    e0 = (z0 + params.w[1:] @ v_rest + params.v_b) / w_sum if ok and w_sum != 0 else 0.0
    return e0 - v_rest

def step(structure: MplPolyStructure, params: MplPolyParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample of the forward model: output from the present state, then the Euler update.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    x : numpy.ndarray, shape (N,)
        Cell voltages before the sample.
    u : float
        Model input ``e`` of the sample.

    Returns
    -------
    y : float
        ``g(w_0 u + sum w_k x_k - V_b)`` (eq. 5.17).
    x_next : array, shape (N,)
        Cell voltages after ``dt`` (eq. 5.6 with eq. 5.16).
    """
    x = np.asarray(x, dtype=float)
    y = output_current(params, params.w[0] * u + params.w[1:] @ x - params.v_b)
    return float(y), x + resistor_current(structure, params, u - x) * structure.dt


def invert_step(structure: MplPolyStructure, params: MplPolyParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of the inverse: ``z = g^-1(y)`` on :func:`output_branch`, the input from the
    output equation with the present state (as eq. 5.13), then the state update (fig. 5.12).

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    x : numpy.ndarray, shape (N,)
        Cell voltages before the sample.
    y : float
        Output to reach at this sample.

    Returns
    -------
    u : float
        Input that gives `y` from the present state.
    x_next : numpy.ndarray
        State after the sample.
    """
    x = np.asarray(x, dtype=float)
    lo, hi, _ = output_branch(structure, params)
    a = lo if np.isfinite(lo) else -1e15
    b = hi if np.isfinite(hi) else 1e15
    # from a +-1e15 bracket to a 1e-15 tolerance takes ~101 halvings: more than brentq's
    # default 100 iterations in the worst case (found by tests/models/test_invert_step_fuzz.py)
    z = brentq(lambda z: output_current(params, z) - y, a, b, xtol=1e-15, rtol=1e-15,
               maxiter=200)
    e = (z - params.w[1:] @ x + params.v_b) / params.w[0]
    return float(e), x + resistor_current(structure, params, e - x) * structure.dt


def _check(structure: MplPolyStructure, params: MplPolyParams, u: np.ndarray,
           name: str) -> np.ndarray:
    check_size(params.n_cells, structure.n_cells, "cells")
    return check_signal(u, name)


def _start(structure: MplPolyStructure, params: MplPolyParams, x0, e0: float) -> np.ndarray:
    if x0 is None:
        return rest_state(structure, params, e0)
    return broadcast_state(x0, structure.n_cells)


def _kernel_args(structure: MplPolyStructure, params: MplPolyParams) -> tuple:
    return (np.ascontiguousarray(params.f), knee_points(structure, params),
            structure.slope_cap / structure.dt, structure.limit, np.ascontiguousarray(params.g))


def _bound(structure: MplPolyStructure, *arrays: np.ndarray) -> float:
    """Divergence threshold of the forward run. With the limit the cells are provably bounded
    (however large a wild cubic makes them), so only non-finite values count; without it, far
    beyond anything a bounded run on these data reaches."""
    if structure.limit:
        return np.inf
    return 1e6 * (1.0 + max(float(np.max(np.abs(a))) for a in arrays))


def simulate(structure: MplPolyStructure, params: MplPolyParams, u: np.ndarray,
             x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the forward model over an input sequence (compiled kernel).

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    u : array, shape (n,)
        Model input ``e`` sampled every ``structure.dt``.
    x0 : array, shape (N,), float or None
        Initial cell voltages; ``None`` starts at rest at the first input,
        ``u_k = e_0 - v*_k`` with ``v*_k`` from :func:`rest_voltages`.

    Returns
    -------
    y : array, shape (n,)
    x_end : array, shape (N,)
        State after the last sample; feeding it back as ``x0`` continues the run exactly.

    Raises
    ------
    FitDivergedError
        If a cell voltage leaves the finite range (only possible with ``limit=False``).
    """
    u = _check(structure, params, u, "u")
    check_rest(structure, params)
    x = _start(structure, params, x0, u[0])
    y, x_end, n_bad = kernels.simulate(u, x, *_kernel_args(structure, params), params.w,
                                       params.v_b, structure.dt, _bound(structure, u, x))
    if n_bad >= 0:
        raise FitDivergedError(f"the model diverged at sample {n_bad} of {u.size} (a cell "
                               f"voltage exceeded 1e6 times the input range or overflowed); "
                               f"without the stability limit (eq. 5.29) forward Euler is "
                               f"unstable here")
    return check_finite_run(y, "mpl-poly"), x_end  # inputs near 1e308 may still overflow


def simulate_reference(structure: MplPolyStructure, params: MplPolyParams, u: np.ndarray,
                       x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Same as :func:`simulate` for bounded runs, as a plain loop over :func:`step`.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Model input ``e`` sampled every ``structure.dt``.
    x0 : numpy.ndarray, float or None, optional
        Initial cell voltages, as for :func:`simulate`.

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Output.
    x_end : numpy.ndarray
        State after the last sample.
    """
    u = _check(structure, params, u, "u")
    x = _start(structure, params, x0, u[0])
    return run_steps(step, structure, params, u, x)


def simulate_with_jacobian(structure: MplPolyStructure, params: MplPolyParams, u: np.ndarray,
                           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Forward output and its exact Jacobian ``dy/dtheta``, shape (n, 5N + 6), columns in the
    order of :meth:`MplPolyParams.to_vector`. The rest start (``x0=None``) moves with the
    parameters: ``du_k(0)/dtheta = (df_k/dtheta)(v*) / f'_k(v*)``. Non-finite on divergence.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Model input ``e`` sampled every ``structure.dt``.
    x0 : numpy.ndarray, float or None, optional
        Initial cell voltages, as for :func:`simulate`.

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Output.
    jac : numpy.ndarray, shape (n, 5N + 6)
        ``dy/dtheta``.
    """
    u = _check(structure, params, u, "u")
    try:
        check_rest(structure, params)
    except FitDivergedError:  # a point outside the domain: the fit rejects the step
        return np.full(u.size, np.nan), np.full((u.size, 5 * structure.n_cells + 6), np.nan)
    x = _start(structure, params, x0, u[0])
    fc, knees, s, limit, gc = _kernel_args(structure, params)
    sens0 = np.zeros((structure.n_cells, 4))
    if x0 is None:
        v_rest = u[0] - x
        slope = resistor_slope(structure, params, v_rest)
        for k in range(structure.n_cells):
            sens0[k] = kernels.cell_gradient(v_rest[k], fc[k], knees[k, 0], knees[k, 1], s,
                                             limit) / slope[k]
    y, jac, n_bad = kernels.simulate_with_jacobian(u, x, sens0, fc, knees, s, limit, gc,
                                                   params.w, params.v_b, structure.dt,
                                                   _bound(structure, u, x))
    if n_bad >= 0:
        y[:], jac[:] = np.nan, np.nan
    return y, jac


def invert(structure: MplPolyStructure, params: MplPolyParams, y: np.ndarray,
           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the inverse model (compensator) over an output sequence.

    Per sample: ``z = g^-1(y_n)`` on the monotone branch of :func:`output_branch` (safeguarded
    Newton), ``e = (z - sum w_k u_k + V_b) / w_0`` with the present state, then the state update.

    Parameters
    ----------
    structure : MplPolyStructure
        The model's structure.
    params : MplPolyParams
        Its parameters.
    y : array, shape (n,)
        Model output (e.g. the sensor signal), sampled every ``structure.dt``.
    x0 : array, shape (N,), float or None
        ``None`` starts at rest: ``u_k = e_0 - v*_k`` with ``e_0`` solving the output equation
        at rest, ``e_0 = (z_0 + sum w_k v*_k + V_b) / sum w`` (``e_0 = 0`` if ``sum w = 0``).

    Returns
    -------
    u_hat : array, shape (n,)
    x_end : array, shape (N,)

    Raises
    ------
    FitDivergedError
        If ``w_0 = 0``, ``g' = 0`` at the rest point, a sample lies outside the range of
        ``g``'s monotone branch (then no inverse exists for it), or the estimate leaves the
        finite range (the inverse dynamics are not guaranteed stable).
    """
    y = _check(structure, params, y, "y")
    if params.w[0] == 0:
        raise FitDivergedError("the model has w_0 = 0, so it has no inverse (eq. 5.13)")
    check_rest(structure, params)
    lo, hi, sign, centre = inverse_branch(structure, params)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # a w_0 near 0
        if x0 is None:
            x = rest_state(structure, params, y[0], inverse=True)
        else:
            x = _start(structure, params, x0, 0.0)
        bound = min(1e6 * (1.0 + np.max(np.abs(y)) + np.max(np.abs(x))), 1e300)
    if not np.all(np.isfinite(x)):
        raise FitDivergedError("the inverse's rest state is not finite: the input at rest "
                               "divides by sum(w), which is too small")
    e_hat, x_end, n_bad, why = kernels.invert(y, x, *_kernel_args(structure, params), lo, hi,
                                              sign, centre, params.w, params.v_b, structure.dt,
                                              bound)
    if why == 1:
        raise FitDivergedError(
            f"the inverse failed at sample {n_bad} of {y.size}: output {y[n_bad]:.4g} is outside "
            f"the range of the output resistor g on its monotone branch [{lo:.4g}, {hi:.4g}]")
    if why == 2:
        raise FitDivergedError(
            f"the inverse model diverged at sample {n_bad} of {y.size} (|e_hat| > 1e6 times the "
            f"output range); the fitted weights make the compensator unstable on this data")
    return e_hat, x_end
