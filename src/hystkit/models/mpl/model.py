"""Modified Power-Law (mPL) hysteresis model, ch. 5.3 of the reference document.

Circuit (fig. 5.5): ``N`` cells, each a capacitor ``C = 1`` charged through a non-linear
resistor whose current is a hyperbolic sine of its voltage (eq. 5.1); a linear output resistor
``R = 1`` sums the weighted cell voltages (eq. 5.2)::

    du_k/dt = f_k(e - u_k),          f_k(v) = I_Sk (exp(v/V_Tk) - exp(-v/V_Tk))    # eq. 5.1, 5.5
    y       = w_0 e + sum_k w_k u_k - V_b                                           # eq. 5.2

integrated with forward Euler (eq. 5.6). The state ``x`` is the vector of cell voltages ``u_k``.

Stability limit (sec. 5.3.5, eq. 5.28-5.29). Forward Euler on a cell is stable only while
``0 < f'(v) dt < 2``. Beyond the points ``x-``/``x+`` where the slope reaches the cap, ``f`` is
continued by straight lines of the capped slope. eq. 5.29 in the document has two typos (the
middle branch reads ``x- > x > x+`` and the lower branch uses ``x+``); the mathematically right
form, used here, is ``f(x-) + s (x - x-)`` for ``x < x-`` and ``f(x) `` for ``x- <= x <= x+``.
The default cap is ``f' dt <= 1`` rather than the marginal ``2``: then ``v -> v - f(v) dt`` is
monotone and contracting, so every Euler step moves ``u_k`` towards the input without
overshoot -- like the continuous RC cell -- and ``u_k`` stays inside the range of the input and
the initial state *for any parameter set*. Any cap in ``(0, 2)`` keeps the model bounded.

Everything here is pure: memory is the explicit state ``x`` passed in and returned.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import FitDivergedError
from .._cells import MAX_CELLS, LimitedCellStructure, check_weighted_cells, state_bound
from .._docs import docfiller
from .._protocol import Record
from .._run import Runs, family_runs
from .._validation import (
    check_magnitude,
    check_range,
    check_structure_size,
    finite_floats,
    freeze_arrays,
)
from . import kernels

fill_doc = docfiller("MplStructure", "MplParams", state="x_cells")

__all__ = [
    "I_S_RANGE",
    "V_T_RANGE",
    "MplParams",
    "MplStructure",
    "invert",
    "invert_step",
    "knee_voltage",
    "output_bound",
    "resistor_current",
    "rest_state",
    "simulate",
    "simulate_reference",
    "step",
]


# The documented parameter domain (normalised units). The fit's box (V_T in [1e-3, 1e3],
# G = 2 I_S / V_T in [1e-4, slope_cap / dt]) lies inside for every dt of the structure's range;
# with these ends and dt >= 1e-9 s no intermediate of a step (sinh at the knee, the capped
# line, its product with dt) comes near the float range.
I_S_RANGE = (1e-12, 1e12)
V_T_RANGE = (1e-6, 1e12)


@dataclass(frozen=True)
class MplStructure(LimitedCellStructure):
    """What does not get fitted: cell count ``N``, sample time and the Euler slope cap
    (:class:`~hystkit.models._cells.CellStructure`; the cap bounds ``f'(v) dt``).

    Parameters
    ----------
    n_cells : int, default 1
        Number of cells ``N`` (1 .. ``MAX_CELLS``).
    dt : float, default 0.025
        Sample time [s] (1e-9 .. 1e6).
    slope_cap : float, default 1.0
        Largest Euler slope ``f'(v) dt`` of a cell resistor (below 2, eq. 5.28; 1 gives
        overshoot-free cells).
    limit : bool, default True
        Apply the stability limit (eq. 5.29, corrected). ``False`` runs the document's
        unbounded sinh resistor, whose forward Euler step diverges once ``f'(v) dt`` passes 2
        (sec. 5.3.3); it exists to reproduce that, not for use. Model files written before
        this field load as limited.
    """

    @property
    def n_params(self) -> int:
        """3N + 2 fitted parameters (sec. 5.3.2)."""
        return 3 * self.n_cells + 2


# The sinh cells' parameters, shared with the ch. 7 compensator (mpl_g.MplGParams).

def freeze_sinh_cells(params: Any) -> None:
    """Set ``n_cells`` and freeze ``i_s``, ``v_t`` (N each) and ``w`` (N + 1) of a record."""
    n = np.size(params.i_s)
    check_structure_size(n, "the number of cells (size of i_s)", MAX_CELLS)  # before copying
    object.__setattr__(params, "n_cells", int(n))
    freeze_arrays(params, i_s=n, v_t=n, w=n + 1)


def sinh_coordinates(params: Any) -> np.ndarray:
    """The optimiser's cell coordinates ``[log G_1, log V_T1, ..., log G_N, log V_TN]``."""
    return np.column_stack([np.log(2 * params.i_s / params.v_t), np.log(params.v_t)]).reshape(-1)


def sinh_from_coordinates(theta: np.ndarray, n_cells: int) -> tuple[np.ndarray, np.ndarray]:
    """``(i_s, v_t)`` from the first ``2 N`` coordinates of :func:`sinh_coordinates`."""
    cells = theta[: 2 * n_cells].reshape(n_cells, 2)
    v_t = np.exp(cells[:, 1])
    return 0.5 * np.exp(cells[:, 0]) * v_t, v_t


@dataclass(frozen=True, eq=False)
class MplParams(Record):
    """Fitted quantities of an mPL model.

    Parameters
    ----------
    i_s : array, shape (N,)
        Saturation current ``I_S`` of each cell's resistor (> 0), eq. 5.1.
    v_t : array, shape (N,)
        Voltage scale ``V_T`` of each cell's resistor (> 0), eq. 5.1.
    w : array, shape (N + 1,)
        VCVS weights ``w_0 .. w_N``, eq. 5.2.
    v_b : float
        Bias voltage ``V_b``, eq. 5.2.

    Notes
    -----
    Domain (checked here): ``I_S`` in ``I_S_RANGE`` (1e-12 .. 1e12), ``V_T`` in
    ``V_T_RANGE`` (1e-6 .. 1e12), ``|w_k|, |V_b| <= MAX_VALUE`` (1e6), at most ``MAX_CELLS``
    cells. With the limit (``MplStructure.limit``, the default) every Euler step moves a
    cell towards its input (overshooting by at most ``slope_cap - 1`` of the gap), so
    ``|y| <= sum |w| B + |V_b|`` with
    ``B = max(max|x0|, max|u| max(1, slope_cap / (2 - slope_cap)))`` (:func:`output_bound`).

    The optimiser sees the vector ``[log G_1, log V_T1, ..., log G_N, log V_TN, w_0..w_N, V_b]``
    with ``G_k = 2 I_Sk / V_Tk`` the small-signal conductance (the inverse time constant of the
    cell). ``G`` and ``V_T`` are far less correlated than ``I_S`` and ``V_T``, and the logs keep
    both positive.
    """

    i_s: np.ndarray
    v_t: np.ndarray
    w: np.ndarray
    v_b: float = 0.0
    n_cells: int = field(init=False)

    def __post_init__(self) -> None:
        freeze_sinh_cells(self)
        finite_floats(self, "v_b")
        check_range(self.i_s, "i_s", *I_S_RANGE, " (eq. 5.1)")
        check_range(self.v_t, "v_t", *V_T_RANGE, " (eq. 5.1)")
        check_magnitude(self.w, "w")
        check_magnitude(self.v_b, "v_b")

    def to_vector(self) -> np.ndarray:
        """Optimiser coordinates (see Notes of the class)."""
        return np.concatenate([sinh_coordinates(self), self.w, [self.v_b]])

    @classmethod
    def from_vector(cls, theta: np.ndarray, n_cells: int) -> MplParams:
        """Inverse of :meth:`to_vector`."""
        theta = np.asarray(theta, dtype=float)
        i_s, v_t = sinh_from_coordinates(theta, n_cells)
        return cls(i_s=i_s, v_t=v_t, w=theta[2 * n_cells: 3 * n_cells + 1],
                   v_b=theta[3 * n_cells + 1])


@fill_doc
def output_bound(structure: MplStructure, params: MplParams, u_max: float,
                 x0_max: float | None = None) -> float:
    """Largest ``|y|`` of a forward run with ``|u| <= u_max`` from ``|x0| <= x0_max``
    (default: at rest, ``x0_max = u_max``); see the Notes of :class:`MplParams`.

    Parameters
    ----------
    %(structure)s
    u_max : float
        Bound on ``|u|`` over the run.
    x0_max : float or None, optional
        Bound on the initial cell voltages ``|x0|``; None means ``u_max``.

    Returns
    -------
    float
        ``|w_0| u_max + sum_k |w_k| B + |V_b|`` with ``B`` the cells' state bound.
    """
    b = state_bound(u_max if x0_max is None else x0_max, u_max, structure.slope_cap)
    return float(abs(params.w[0]) * u_max + np.abs(params.w[1:]).sum() * b + abs(params.v_b))


@fill_doc
def knee_voltage(structure: MplStructure, params: MplParams) -> np.ndarray:
    """Voltage ``x+`` (= ``-x-``) beyond which each cell's resistor is a straight line.

    Solves ``f'(x) = slope_cap / dt`` for the sinh resistor, ``f'(v) = G cosh(v / V_T)``;
    zero when even the small-signal slope ``G`` exceeds the cap (the cell is then linear);
    ``+inf`` without the limit (``structure.limit`` false: the sinh everywhere). A structure
    without a ``limit`` field (the mpl-g family's) is limited.

    %(records_parameters)s

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``x+`` of each cell (>= 0).
    """
    g = 2 * params.i_s / params.v_t
    if not getattr(structure, "limit", True):
        return np.full(np.shape(g), np.inf)
    ratio = structure.slope_cap / (structure.dt * g)
    return np.where(ratio > 1, params.v_t * np.arccosh(np.maximum(ratio, 1.0)), 0.0)


@fill_doc
def resistor_current(structure: MplStructure, params: MplParams, v: np.ndarray) -> np.ndarray:
    """Limited cell-resistor currents ``f_k,lim(v)`` (eq. 5.1 with eq. 5.29, corrected):
    ``2 I_S sinh(v / V_T)`` inside the knees, the straight line of slope ``slope_cap / dt``
    beyond.

    %(cell_voltages)s
    """
    v = np.asarray(v, dtype=float)
    knee = knee_voltage(structure, params)
    cap = structure.slope_cap / structure.dt
    inside = np.abs(v) <= knee
    v_in = np.clip(v, -knee, knee)
    f_in = 2 * params.i_s * np.sinh(v_in / params.v_t)
    return np.where(inside, f_in, f_in + cap * (v - v_in))


@fill_doc
def step(structure: MplStructure, params: MplParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample of the forward model: output ``y = w_0 u + sum w_k x_k - V_b`` (eq. 5.2) from
    the present state and the model input ``u = e``, then the Euler update of the cell voltages
    over ``dt`` (eq. 5.6).

    %(step)s
    """
    x = np.asarray(x, dtype=float)
    y = params.w[0] * u + params.w[1:] @ x - params.v_b
    x_next = x + resistor_current(structure, params, u - x) * structure.dt
    return float(y), x_next


@fill_doc
def invert_step(structure: MplStructure, params: MplParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of the analytical inverse (eq. 5.13-5.14, order of fig. 5.12).

    The input estimate is solved from the output equation with the present state first, and
    only then does the state advance with that estimate.

    Parameters
    ----------
    %(structure)s
    %(state)s
    %(y_step)s

    Returns
    -------
    u_hat : float
        ``(y - sum w_k x_k + V_b) / w_0`` (eq. 5.13).
    x_next : array, shape (N,)
        Cell voltages after ``dt``, driven by ``u_hat`` (eq. 5.14).
    """
    x = np.asarray(x, dtype=float)
    u_hat = (y - params.w[1:] @ x + params.v_b) / params.w[0]
    x_next = x + resistor_current(structure, params, u_hat - x) * structure.dt
    return float(u_hat), x_next


@fill_doc
def rest_state(structure: MplStructure, params: MplParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Cell voltages at rest under a constant input ``value``: each cell equals its drive.
    With ``inverse``, ``value`` is an output and the drive is the input at rest,
    ``(y + V_b) / sum(w)`` (0 when ``sum(w) = 0``).

    Parameters
    ----------
    %(structure)s
    value : float
        Constant input (with `inverse`: output).
    inverse : bool, default False
        Rest state of the inverse.

    Returns
    -------
    numpy.ndarray, shape (N,)
    """
    if inverse:
        w_sum = float(np.sum(params.w))
        value = (value + params.v_b) / w_sum if w_sum != 0 else 0.0
    return np.full(structure.n_cells, float(value))


def _forward(structure: MplStructure, params: MplParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    y, x_end = kernels.simulate(u, x, params.i_s, params.v_t, params.w, params.v_b,
                                knee_voltage(structure, params),
                                structure.slope_cap / structure.dt, structure.dt)
    if not structure.limit:
        _check_unlimited_run(structure, params, y, u, x)
    return y, x_end


def _check_unlimited_run(structure: MplStructure, params: MplParams, y: np.ndarray,
                         u: np.ndarray, x0: np.ndarray) -> None:
    """Raise FitDivergedError, naming the first bad sample, if the unlimited model's output
    left the finite range or went past 1e6 times the bound a limited run keeps to."""
    limited = output_bound(structure, params, float(np.max(np.abs(u))),
                           float(np.max(np.abs(x0))))
    bad = np.flatnonzero(~(np.abs(y) <= 1e6 * (1.0 + limited)))
    if bad.size:
        raise FitDivergedError(
            f"the unlimited sinh mPL (--no-limit) diverged at sample {int(bad[0]) + 1} of "
            f"{y.size}: without the stability limit (eq. 5.29) its Euler step grows once "
            f"f'(v) dt passes 2 (sec. 5.3.3)")


def _inverse(structure: MplStructure, params: MplParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    u_hat, x_end, n_bad = kernels.invert(y, x, params.i_s, params.v_t, params.w, params.v_b,
                                         knee_voltage(structure, params),
                                         structure.slope_cap / structure.dt, structure.dt)
    if n_bad >= 0:
        raise FitDivergedError(
            f"the inverse model diverged at sample {n_bad} of {y.size} (|u_hat| > 1e6 times the "
            f"input range); the fitted weights make the compensator unstable on this data")
    return u_hat, x_end


RUNS = Runs(label="mpl", step=step, n_state=lambda structure, params: structure.n_cells,
            rest_state=rest_state, forward=_forward, inverse=_inverse, check=check_weighted_cells)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the mPL model",
    notes="The input is the source voltage ``e`` and the state the cell voltages ``u_k``; the "
          "rest start ``u_k = e_0`` is the synchronised start of eq. 2.21-2.22 rather than the "
          "document's zero state. With ``structure.limit`` false (the unlimited sinh) a run "
          "that grows past 1e6 times the limited bound raises FitDivergedError.",
    inverse_notes="eq. 5.13-5.14: ``u_hat = (y - sum w_k x_k + V_b) / w_0`` from the present "
                  "state, then the cells advance with it. No inverse exists for ``w_0 = 0``; "
                  "the inverse's cells see ``-(1 + w_k / w_0)`` times their own voltage, so its "
                  "stability depends on the weights.")
