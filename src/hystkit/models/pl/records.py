"""The Power-Law model's records: its structure and parameters with their documented domain
(normalised units), the output bound and the output basis (eq. 2.16-2.18, sec. 2.1.7; the
equations are in :mod:`.model`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._cells import DT_RANGE, MAX_CELLS, SLOPE_CAP_MIN, state_bound
from .._docs import docfiller
from .._protocol import Record
from .._validation import (
    check_dt,
    check_magnitude,
    check_range,
    check_slope_cap,
    check_structure_size,
    finite_floats,
    freeze_arrays,
)

fill_doc = docfiller("PlStructure", "PlParams")

# Limits and the documented parameter domain (normalised units, eq. 5.10). The fit's box
# (I_T in [1e-6, 1e4], V_T in [1e-3, 2], a_j >= 0.05 with sum a_j = M, |w| <= 100) lies
# inside. A_RANGE is what keeps the output bounded: y = f^-1(u) divides by the slopes a_j, so
# a = 1e-30 turned |u| <= 1 into |y| = 1e29.
MAX_BASIS = 1000
POWER_RANGE = (1.01, 1000.0)
I_T_RANGE = (1e-12, 1e12)
V_T_RANGE = (1e-9, 1e6)
A_RANGE = (1e-3, 1e3)


@dataclass(frozen=True)
class PlStructure(Record):
    """Structural (not least-squares) parameters: N, p, M, S of the exhaustive search, and dt.

    Parameters
    ----------
    n_cells : int
        Cells ``N`` (>= 1).
    power : float
        Exponent ``p`` (> 1) of the cell resistors' middle part, eq. 2.16.
    n_basis : int
        Number ``M`` (>= 1) of PWL basis functions of the output resistor, eq. 2.17.
    smoothing : float
        ``S`` (>= 0): weight of the penalty on slope changes of ``f`` between neighbouring basis
        segments in the weight fit (per sample, relative to the mean squared equation error);
        it has no effect on simulation. Table 5.1 uses 0.001.
    dt : float
        Sample time [s].
    slope_cap : float
        ``G dt`` of the straight branches, the largest Euler slope (< 2, eq. 5.28; 1: no overshoot).

    Notes
    -----
    Limits (checked first, before anything is allocated): ``1 <= n_cells <= 1000``,
    ``1 <= n_basis <= MAX_BASIS`` (1000), ``power`` in ``POWER_RANGE`` (1.01 .. 1000), ``dt``
    in 1e-9 .. 1e6 s, ``slope_cap`` at least 1e-6.
    """

    n_cells: int = 1
    power: float = 21.0
    n_basis: int = 1
    smoothing: float = 0.001
    dt: float = 0.025
    slope_cap: float = 1.0

    def __post_init__(self) -> None:
        check_structure_size(self.n_cells, "n_cells", MAX_CELLS)
        check_structure_size(self.n_basis, "n_basis", MAX_BASIS)
        check_range(self.power, "power p", *POWER_RANGE, " (eq. 2.16 divides by p - 1)")
        if not (np.isfinite(self.smoothing) and self.smoothing >= 0):
            raise ValueError(f"smoothing S must be >= 0, got {self.smoothing!r}")
        check_dt(self.dt)
        check_range(self.dt, "dt", *DT_RANGE, " s")
        check_slope_cap(self.slope_cap)
        check_range(self.slope_cap, "slope_cap", SLOPE_CAP_MIN, 2.0, " (below 2: eq. 5.28)")

    @property
    def n_params(self) -> int:
        """Parameters as table 5.1 counts them: w_0..w_N, V_b, a_1..a_M, I_T, V_T (N + M + 4).

        One of them is redundant: scaling ``w``, ``V_b`` and ``a`` together leaves ``i`` unchanged;
        the fit fixes the mean slope of ``f`` to 1.
        """
        return self.n_cells + self.n_basis + 4


@dataclass(frozen=True, eq=False)
class PlParams(Record):
    """Least-squares parameters of a PL model.

    Parameters
    ----------
    i_t : float
        Current ``I_T`` (> 0) of eq. 2.16 [1/s with C = 1 and normalised voltages].
    v_t : float
        Threshold step ``V_T`` (> 0); cell ``k`` has its threshold at ``k V_T``.
    w : array, shape (N + 1,)
        VCVS weights ``w_0 .. w_N``, eq. 2.18.
    v_b : float
        Bias ``V_b``, eq. 2.18.
    a : array, shape (M,)
        Slopes ``a_j`` (> 0) of the output resistor on its M segments, eq. 2.17.

    Notes
    -----
    Domain (checked here): ``I_T`` in ``I_T_RANGE`` (1e-12 .. 1e12), ``V_T`` in ``V_T_RANGE``
    (1e-9 .. 1e6), ``a_j`` in ``A_RANGE`` (1e-3 .. 1e3), ``|w_k|, |V_b| <= 1e6``, at most 1000
    cells and basis slopes. Every Euler step moves a cell towards its input, so
    ``|y| <= (sum |w| B + |V_b|) / min(a)`` with ``B = max(max|x0|, max|u| max(1,
    slope_cap / (2 - slope_cap)))`` (:func:`output_bound`).
    """

    i_t: float
    v_t: float
    w: np.ndarray
    v_b: float = 0.0
    a: np.ndarray = (1.0,)
    n_cells: int = field(init=False)
    n_basis: int = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "n_cells", int(np.size(self.w)) - 1)
        object.__setattr__(self, "n_basis", int(np.size(self.a)))
        if self.n_cells < 1 or self.n_basis < 1:
            raise ValueError("w needs N + 1 >= 2 values and a at least one")
        check_structure_size(self.n_cells, "the number of cells (size of w minus 1)", MAX_CELLS)
        check_structure_size(self.n_basis, "the number of basis slopes (size of a)", MAX_BASIS)
        freeze_arrays(self, w=self.n_cells + 1, a=self.n_basis)
        finite_floats(self, "i_t", "v_t", "v_b")
        check_range(self.i_t, "i_t", *I_T_RANGE, " (eq. 2.16)")
        check_range(self.v_t, "v_t", *V_T_RANGE, " (eq. 2.16)")
        check_range(self.a, "a (output resistor slopes)", *A_RANGE,
                    ": y = f^-1(u) divides by them")
        check_magnitude(self.w, "w")
        check_magnitude(self.v_b, "v_b")


@fill_doc
def output_bound(structure: PlStructure, params: PlParams, u_max: float,
                 x0_max: float | None = None) -> float:
    """Largest ``|y|`` of a forward run with ``|u| <= u_max`` from ``|x0| <= x0_max``
    (default: at rest, ``x0_max = u_max``); see the Notes of :class:`PlParams`.

    Parameters
    ----------
    %(structure)s
    %(u_max)s
    x0_max : float, optional
        Largest initial state magnitude; default `u_max` (a start at rest).

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    b = state_bound(u_max if x0_max is None else x0_max, u_max, structure.slope_cap)
    u = abs(params.w[0]) * u_max + np.abs(params.w[1:]).sum() * b + abs(params.v_b)
    return float(u / np.min(params.a))


def basis_breakpoints(n_basis: int) -> np.ndarray:
    """Breakpoints ``b_0 .. b_M`` of the output basis: M equal segments of [-1, 1], eq. 2.17.

    Parameters
    ----------
    n_basis : int
        Number ``M`` of segments.

    Returns
    -------
    numpy.ndarray, shape (M + 1,)
        The breakpoints, from -1 to 1.
    """
    return np.linspace(-1.0, 1.0, n_basis + 1)
