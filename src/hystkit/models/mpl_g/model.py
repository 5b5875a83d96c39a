"""The ch. 7 compensator: sinh cells with a cubic output resistor ``g`` (sec. 7.2).

Sec. 7.2 builds ``S_m^comp`` from "the first modification of the original PL model where a
hyperbolic function is used to describe the non-linear resistor for sub-circuit (a)" (the mPL,
eq. 5.1-5.6), "extended with a second non-linear resistor at the output, represented by a 3rd
order polynomial of the form described by 5.16"; the output equation is then eq. 5.17::

    du_k/dt = f_k(e - u_k),          f_k(v) = I_Sk (exp(v/V_Tk) - exp(-v/V_Tk))    # eq. 5.1, 5.5
    i       = g(w_0 e + sum_k w_k u_k - V_b),   g(z) = g_0 + g_1 z + g_2 z^2 + g_3 z^3  # eq. 5.17

integrated with forward Euler (eq. 5.6) and the cells limited by eq. 5.29 (corrected) exactly
as in the mPL: the cells, their knees and their limit are the ``mpl`` family's functions, the
output resistor and its inverse are the ``mpl-poly`` family's, imported, not copied. ``g``
holds the plain coefficients (the document's ``g_2^2, g_3^3`` form of eq. 5.16 is a
parametrisation; ``mpl_poly.presets`` converts printed values). The state ``x`` is the vector of
cell voltages; a sinh cell rests at ``v = 0`` (it is odd and increasing), so at rest
``u_k = e``.

Inverse (eq. 5.13-5.14 with ``g``): ``z = g^-1(i)`` on the monotone branch of ``g`` through
the rest point ``z = -V_b`` (the output voltage at rest at ``e = 0``), then
``e = (z - sum w_k u_k + V_b) / w_0`` with the present state, then the state update
(fig. 5.12).

Everything here is pure: memory is the explicit state ``x`` passed in and returned.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._cells import CellStructure, check_weighted_cells
from .._cubic_output import output_invert_step, output_step
from .._docs import docfiller
from .._protocol import Record
from .._run import Runs, family_runs
from .._validation import (
    check_magnitude,
    check_range,
    check_signal,
    check_size,
    finite_floats,
    frozen_shaped,
)
from ..mpl.model import (
    I_S_RANGE,
    V_T_RANGE,
    freeze_sinh_cells,
    knee_voltage,
    resistor_current,
    sinh_coordinates,
    sinh_from_coordinates,
)
from ..mpl_poly.kernels import solve_output
from ..mpl_poly.records import check_output_cubic
from ..mpl_poly.resistors import output_current, output_root, output_slope
from ..mpl_poly.rest import branch_around, check_branch_inverse
from . import kernels

fill_doc = docfiller("MplGStructure", "MplGParams", state="x_cells")

__all__ = [
    "WEIGHT_SUM_FLOOR",
    "MplGParams",
    "MplGStructure",
    "inverse_branch",
    "invert",
    "invert_step",
    "knee_voltage",
    "output_branch",
    "output_current",
    "output_slope",
    "resistor_current",
    "rest_state",
    "simulate",
    "simulate_reference",
    "simulate_with_jacobian",
    "step",
]

WEIGHT_SUM_FLOOR = 1.0
"""A weight-sum bound (``weight_sum_max``) must exceed this: the gauge fixes ``w_0 = 1``."""


@dataclass(frozen=True)
class MplGStructure(CellStructure):
    """What does not get fitted: cell count ``N``, sample time and the Euler slope cap
    (:class:`~hystkit.models._cells.CellStructure`; the cap bounds ``f'(v) dt``).

    Parameters
    ----------
    n_cells : int, default 1
        Number of sinh cells ``N``.
    dt : float, default 0.025
        Sample time [s].
    slope_cap : float, default 1.0
        Largest Euler slope ``f' dt`` of a cell; beyond its knee a sinh resistor goes on straight
        (eq. 5.29).
    """

    @property
    def n_params(self) -> int:
        """``3N + 6`` fitted parameters (9 for the document's N = 1); ``3N + 4`` identifiable
        (``fit.canonical``)."""
        return 3 * self.n_cells + 6


@dataclass(frozen=True, eq=False)
class MplGParams(Record):
    """Fitted quantities of the ch. 7 compensator.

    Parameters
    ----------
    i_s, v_t : array, shape (N,)
        Saturation current ``I_S`` and voltage scale ``V_T`` of each sinh cell (> 0), eq. 5.1.
    g : array, shape (4,)
        Cubic coefficients ``g_0..g_3`` of the output resistor (eq. 5.16-5.17).
    w : array, shape (N + 1,)
        VCVS weights ``w_0 .. w_N``.
    v_b : float
        Bias voltage ``V_b``.

    Notes
    -----
    Domain (checked here): ``I_S``, ``V_T`` as the mPL (1e-12 .. 1e12, 1e-6 .. 1e12),
    ``|g_j| <= 1e9`` and each ``g_j`` 0 or at least 1e-200 in magnitude (as the mpl-poly's
    ``g``), ``|w_k|, |V_b| <= 1e6``, at most 1000 cells. With ``slope_cap <= 1`` every cell stays
    within the range of its inputs and initial state, so the output is bounded by
    ``sum_j |g_j| Z^j`` with ``Z = sum |w| max|u| + |V_b|``.

    The optimiser sees ``[log G_1, log V_T1, ..., log G_N, log V_TN, g_0..g_3, w_0..w_N, V_b]``
    with ``G_k = 2 I_Sk / V_Tk`` the cell's small-signal conductance (as the mPL).
    """

    i_s: np.ndarray
    v_t: np.ndarray
    g: np.ndarray
    w: np.ndarray
    v_b: float = 0.0
    n_cells: int = field(init=False)

    def __post_init__(self) -> None:
        freeze_sinh_cells(self)
        object.__setattr__(self, "g", frozen_shaped(self.g, (4,), "g"))
        finite_floats(self, "v_b")
        check_range(self.i_s, "i_s", *I_S_RANGE, " (eq. 5.1)")
        check_range(self.v_t, "v_t", *V_T_RANGE, " (eq. 5.1)")
        check_output_cubic(self.g)
        check_magnitude(self.w, "w")
        check_magnitude(self.v_b, "v_b")

    def to_vector(self) -> np.ndarray:
        """Optimiser coordinates (see Notes of the class)."""
        return np.concatenate([sinh_coordinates(self), self.g, self.w, [self.v_b]])

    @classmethod
    def from_vector(cls, theta: np.ndarray, n_cells: int) -> MplGParams:
        """Inverse of :meth:`to_vector`."""
        theta = np.asarray(theta, dtype=float)
        i_s, v_t = sinh_from_coordinates(theta, n_cells)
        rest = theta[2 * n_cells:]
        return cls(i_s=i_s, v_t=v_t, g=rest[:4], w=rest[4:n_cells + 5], v_b=rest[n_cells + 5])


@fill_doc
def output_branch(params: MplGParams) -> tuple[float, float, float]:
    """The monotone branch of ``g`` the inverse uses: ``(lo, hi, sign)``.

    It is the largest interval around the rest point ``z_rest = -V_b`` (the output voltage at
    rest at ``e = 0``, the centre of centred data) on which ``g'`` keeps its sign; ``+-inf``
    where ``g'`` has no root on that side.

    Parameters
    ----------
    %(params)s

    Returns
    -------
    %(branch)s

    %(no_branch)s
    """
    return branch_around(params, -params.v_b)


@fill_doc
def inverse_branch(params: MplGParams) -> tuple[float, float, float, float]:
    """``(lo, hi, sign, centre)``: :func:`output_branch` and ``z_rest = -V_b``, the
    arguments of ``mpl_poly.kernels.solve_output``.

    Parameters
    ----------
    %(params)s

    Returns
    -------
    lo, hi, sign : float
        As :func:`output_branch`.
    centre : float
        The rest point ``z_rest = -V_b``.

    Raises
    ------
    FitDivergedError
        As :func:`output_branch`.
    """
    return (*output_branch(params), -float(params.v_b))


def _solve(params: MplGParams, y: float) -> tuple[float, bool]:
    return solve_output(float(y), np.ascontiguousarray(params.g), *inverse_branch(params))


@fill_doc
def rest_state(structure: MplGStructure, params: MplGParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Cells at rest, ``u_k = e_0``, shape (N,).

    Forward: ``e_0`` is the constant input ``value``. Inverse (``value`` a constant output):
    ``e_0 = (z_0 + V_b) / sum w`` with ``g(z_0) = value`` on the branch, the input at which the
    model rests with that output; ``e_0 = 0`` if ``value`` is outside the branch's range or
    ``sum w = 0``. :func:`simulate` / :func:`invert` start here for ``x0=None``.

    Parameters
    ----------
    %(structure)s
    %(rest_value)s

    Returns
    -------
    numpy.ndarray, shape (N,)
        Cell voltages at rest.
    """
    if inverse:
        z0, ok = _solve(params, value)
        w_sum = float(params.w.sum())
        value = (z0 + params.v_b) / w_sum if ok and w_sum != 0 else 0.0
    return np.full(structure.n_cells, float(value))


@fill_doc
def step(structure: MplGStructure, params: MplGParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample of the forward model: output ``y = g(w_0 u + sum w_k x_k - V_b)`` (eq. 5.17)
    from the present state and the model input ``u = e``, then the Euler update of the cell
    voltages over ``dt`` (eq. 5.6, sinh resistors limited by eq. 5.29).

    %(step)s
    """
    return output_step(structure, params, x, u, output_current, resistor_current)


@fill_doc
def invert_step(structure: MplGStructure, params: MplGParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of the inverse (readable reference): ``z = g^-1(y)`` on
    :func:`output_branch` by bracketed root finding, the input from the output equation with
    the present state (eq. 5.13), then the state update (fig. 5.12).

    Parameters
    ----------
    %(structure)s
    %(state)s
    %(y_step)s

    Returns
    -------
    %(u_step)s
    x_next : numpy.ndarray, shape (N,)
        Cell voltages after the sample.

    Raises
    ------
    ValueError
        If ``y`` is outside the range of the branch (no input gives it).
    """
    lo, hi, _ = output_branch(params)
    return output_invert_step(structure, params, x, output_root(params, y, lo, hi),
                              resistor_current)


def _cell_args(structure: MplGStructure, params: MplGParams) -> tuple:
    return (params.i_s, params.v_t, knee_voltage(structure, params),
            structure.slope_cap / structure.dt, structure.dt)


def _forward(structure: MplGStructure, params: MplGParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return kernels.simulate(u, x, np.ascontiguousarray(params.g), params.w, float(params.v_b),
                            *_cell_args(structure, params))


def _inverse(structure: MplGStructure, params: MplGParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    lo, hi, sign, centre = inverse_branch(params)
    bound = min(1e6 * (1.0 + np.max(np.abs(y)) + np.max(np.abs(x))), 1e300)
    e_hat, x_end, n_bad, why = kernels.invert(y, x, np.ascontiguousarray(params.g), lo, hi,
                                              sign, centre, params.w, float(params.v_b),
                                              *_cell_args(structure, params), bound)
    check_branch_inverse(why, n_bad, y, lo, hi)
    return e_hat, x_end


RUNS = Runs(label="mpl-g", step=step, n_state=lambda structure, params: structure.n_cells,
            rest_state=rest_state, forward=_forward, inverse=_inverse, check=check_weighted_cells)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the mPL model with a general output resistor",
    notes="The input is ``e`` (normalised units), the state the cell voltages ``u_k`` (at rest: "
          "``u_k = e_0``).",
    inverse_notes="The compensator of a forward fit. FitDivergedError if ``w_0 = 0``, "
                  "``g' = 0`` at the rest point, a sample lies outside the range of ``g``'s "
                  "monotone branch (no input gives it), or the estimate leaves the finite range "
                  "(the inverse's cells see ``-(1 + w_k / w_0)`` times their own voltage).")


@fill_doc
def simulate_with_jacobian(structure: MplGStructure, params: MplGParams,
                           u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Forward output from rest and its exact Jacobian ``dy/dtheta`` (forward sensitivities).

    Parameters
    ----------
    %(structure)s
    u : numpy.ndarray, shape (n,)
        Model input ``e`` sampled every ``structure.dt``; the run starts at rest at ``u[0]``.

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Model output.
    jacobian : numpy.ndarray, shape (n, 3N + 6)
        ``dy/dtheta``, columns in the order of :meth:`MplGParams.to_vector`.
    """
    check_size(params.n_cells, structure.n_cells, "cells")
    u = check_signal(u, "u")
    x = np.full(structure.n_cells, u[0])
    return kernels.simulate_with_jacobian(u, x, np.ascontiguousarray(params.g), params.w,
                                          float(params.v_b), *_cell_args(structure, params))


