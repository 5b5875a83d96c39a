"""The polynomial mPL model's records: structure and parameters with their documented domain
(normalised units) and the limits of the cubic coefficients (the equations are in
:mod:`.resistors`, :mod:`.rest` and :mod:`.model`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._cells import MAX_CELLS, LimitedCellStructure
from .._protocol import Record
from .._validation import (
    check_magnitude,
    check_range,
    check_structure_size,
    finite_floats,
    frozen_shaped,
)

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


def check_output_cubic(g: np.ndarray) -> None:
    """The output resistor's cubic (mpl-poly, mpl-g): ``|g_j| <= POLY_MAX`` and each ``g_j``
    0 or at least ``G_MIN`` in magnitude; ValueError naming the first one that is not."""
    check_magnitude(g, "g", POLY_MAX)
    tiny = (g != 0) & (np.abs(g) < G_MIN)
    if np.any(tiny):
        raise ValueError(f"g must be 0 or at least {G_MIN:g} in magnitude (its roots are "
                         f"solved for), got {float(g[np.argmax(tiny)])!r}")


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


@dataclass(frozen=True)
class MplPolyStructure(LimitedCellStructure):
    """What does not get fitted: cell count, sample time, Euler slope cap (outside the knees)
    and the limit switch (:class:`~hystkit.models._cells.LimitedCellStructure`).

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
        check_output_cubic(self.g)
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
