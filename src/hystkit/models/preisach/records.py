"""The classical Preisach model's records: structure and parameters with their limits, the
input grid and the Everett function of the cell masses (appendix 9.3-9.5; the staircase is in
:mod:`.staircase`, the runs in :mod:`.model`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._docs import docfiller
from .._protocol import Record
from .._validation import (
    check_dt,
    check_magnitude,
    check_structure_size,
)

# The Parameters section of the functions of the Everett nodes alone (%(everett_nodes)s).
_ENTRIES = {"everett_nodes": """Parameters
----------
e : numpy.ndarray, shape (L, L)
    Everett nodes (lower triangle)."""}
fill_doc = docfiller(params="PreisachParams", entries=_ENTRIES)

# Limits. The fit's design matrix holds n_samples x L (L - 1) / 2 floats: at L = 128 and 8000
# samples 0.5 GB (measured: 1.5 GB peak, 2.5 min); L = 512 would need 8.4 GB. A run holds one
# (L, L) table (128 kB) and a staircase of `capacity` floats (8 MB at MAX_CAPACITY).
MAX_LEVELS = 128
MAX_CAPACITY = 1 << 20
# Everett values and offsets in normalised units (eq. 5.10: a major loop spanning [-1, 1] has
# F(1, -1) = 1); sums of 128^2 of them stay finite.
MAX_VALUE = 1e6
# The inverse divides by the major loop's rise beyond saturation: one smaller than this
# fraction of the total mass turns an output step into an input step 1e9 times larger.
MIN_RISE = 1e-9

INVERT_TOL = 1e-12  # bisection bracket width on the normalised input before interpolating


@dataclass(frozen=True)
class PreisachStructure(Record):
    """What does not get fitted.

    Parameters
    ----------
    levels : int
        Grid levels ``L`` over [-1, 1] (``2 .. MAX_LEVELS``, 128): ``L (L - 1) / 2`` Preisach
        cells.
    dt : float
        Sample time [s]. The model is rate independent; ``dt`` only records the sampling.
    capacity : int
        Size of the staircase buffer (``2 L + 2 .. MAX_CAPACITY``, 2^20); per-sample cost does
        not depend on it.
        It is also the fixed length of the loop state (``capacity + 1`` floats, see
        :func:`pack_state`). When the staircase is about to fill, the innermost closed loop is
        forgotten (module docstring): the memory degrades gracefully, never overflows.
    smoothing : float
        Fit only: weight of the smoothness penalty on the Preisach density (see
        ``models/preisach/fit.py``); 0 gives plain bounded least squares.
    orientation : {"auto", "counterclockwise", "clockwise"}
        Fit only: sign of the hysteretic (off-diagonal) weights. Counter-clockwise loops
        (output lags input) need ``mu >= 0``, clockwise loops ``mu <= 0`` off the diagonal;
        ``auto`` fits both and keeps the better. The diagonal (reversible) weights are
        non-negative in all cases.
    """

    levels: int = 20
    dt: float = 0.025
    capacity: int = 1024
    smoothing: float = 1e-5
    orientation: str = "auto"

    def __post_init__(self) -> None:
        check_structure_size(self.levels, "levels", MAX_LEVELS, low=2)  # first: L^2 tables
        check_dt(self.dt)
        check_structure_size(self.capacity, "capacity", MAX_CAPACITY)
        if self.capacity < 2 * self.levels + 2:
            # worded without "levels", so that a model file's error names this key
            raise ValueError(f"capacity must be at least 2 L + 2 = {2 * self.levels + 2} for "
                             f"a grid of L = {self.levels}, got {self.capacity!r}")
        if not (np.isfinite(self.smoothing) and self.smoothing >= 0):
            raise ValueError(f"smoothing must be finite and >= 0, got {self.smoothing!r}")
        if self.orientation not in ("auto", "counterclockwise", "clockwise"):
            raise ValueError(f"orientation must be 'auto', 'counterclockwise' or 'clockwise', "
                             f"got {self.orientation!r}")


def grid(levels: int) -> np.ndarray:
    """The ``L`` equally spaced input levels ``h_i`` over [-1, 1], shape (L,).

    Parameters
    ----------
    levels : int
        Number of levels ``L``.

    Returns
    -------
    numpy.ndarray, shape (L,)
        The levels.
    """
    return np.linspace(-1.0, 1.0, int(levels))


def everett_from_masses(masses: np.ndarray) -> np.ndarray:
    """Everett nodes ``E`` (L, L) from cell masses (L-1, L-1), lower triangle incl. diagonal.

    ``masses[i, j]`` (``j < i``) is the weight on the square ``alpha in [h_i, h_i+1]``,
    ``beta in [h_j, h_j+1]``; ``masses[i, i]`` the weight along the diagonal segment. Then
    ``E[a, b] = sum of masses[i, j] over b <= j <= i < a`` (eq. 9.6 on the grid).

    Parameters
    ----------
    masses : numpy.ndarray, shape (L - 1, L - 1)
        Cell masses, lower triangle including the diagonal.

    Returns
    -------
    numpy.ndarray, shape (L, L)
        Everett nodes ``E``, strictly lower triangle.
    """
    m = np.tril(np.asarray(masses, dtype=float))
    n_cells = m.shape[0]
    inner = np.cumsum(np.cumsum(m[:, ::-1], axis=1)[:, ::-1], axis=0)  # rows < a, cols >= b
    e = np.zeros((n_cells + 1, n_cells + 1))
    e[1:, :-1] = inner
    return np.tril(e, -1)


@fill_doc
def masses_from_everett(e: np.ndarray) -> np.ndarray:
    """Inverse of :func:`everett_from_masses`: mixed second differences of ``E``.

    %(everett_nodes)s

    Returns
    -------
    numpy.ndarray, shape (L - 1, L - 1)
        Cell masses, lower triangle including the diagonal.
    """
    e = np.tril(np.asarray(e, dtype=float), -1)
    m = e[1:, :-1] - e[1:, 1:] - e[:-1, :-1] + e[:-1, 1:]
    return np.tril(m)


@fill_doc
def antisymmetric(e: np.ndarray) -> np.ndarray:
    """``E - E^T``: the extension the bilinear interpolation runs on (zero diagonal).

    %(everett_nodes)s

    Returns
    -------
    numpy.ndarray, shape (L, L)
        ``E - E^T``.
    """
    return e - e.T


@dataclass(frozen=True, eq=False)
class PreisachParams(Record):
    """Fitted quantities: the Everett function on the grid and the output offset.

    Parameters
    ----------
    everett : array, shape (L, L)
        ``everett[i, j] = F(h_i, h_j)`` for ``i > j`` (eq. 9.6); diagonal and upper triangle
        must be zero (``F(a, a) = 0``; ``F`` is defined for ``alpha >= beta`` only).
    offset : float
        Output offset ``y_0 = (f+ + f-) / 2``.

    Notes
    -----
    Domain (checked here): ``|F|, |y_0| <= MAX_VALUE`` (1e6), ``2 <= L <= MAX_LEVELS``. Then
    ``|y - y_0| <= sum |m| max(1, |u|)`` with ``m`` the cell masses (:func:`output_bound`).
    The inverse needs a rising major loop, ``F(1, -1) >= MIN_RISE sum |m|``, and returns
    ``|u| <= 1 + (|y - y_0| + sum |m|) / F(1, -1)``.
    """

    everett: np.ndarray
    offset: float = 0.0

    def __post_init__(self) -> None:
        check_structure_size(len(self.everett) if np.ndim(self.everett) else 1,
                             "levels (rows of everett)", MAX_LEVELS)  # before the copy
        e = np.array(self.everett, dtype=float)
        if e.ndim != 2 or e.shape[0] != e.shape[1] or e.shape[0] < 2:
            raise ValueError(f"everett must be a square (L, L) array with L >= 2, got shape "
                             f"{e.shape}")
        if not np.all(np.isfinite(e)) or not np.isfinite(self.offset):
            raise ValueError("everett and offset must be finite")
        if np.any(np.triu(e) != 0):
            raise ValueError("everett must be zero on and above the diagonal (F(a, a) = 0)")
        check_magnitude(e, "everett", MAX_VALUE)
        check_magnitude(self.offset, "offset", MAX_VALUE)
        e.setflags(write=False)
        object.__setattr__(self, "everett", e)
        object.__setattr__(self, "offset", float(self.offset))

    @property
    def levels(self) -> int:
        return self.everett.shape[0]

    @classmethod
    def from_masses(cls, masses: np.ndarray, offset: float = 0.0) -> PreisachParams:
        """From cell masses (L-1, L-1), see :func:`everett_from_masses`."""
        return cls(everett=everett_from_masses(masses), offset=offset)

    def masses(self) -> np.ndarray:
        """Cell masses (L-1, L-1); all >= 0 exactly when the weight ``mu`` is non-negative."""
        return masses_from_everett(self.everett)

    # Model files store the strict lower triangle row by row (no zeros); Record's full-matrix
    # form would change the file format, so the old one is kept.
    def to_dict(self) -> dict:
        rows = [self.everett[i, :i].tolist() for i in range(1, self.levels)]
        return {"everett": rows, "offset": self.offset}

    @classmethod
    def from_dict(cls, d: dict) -> PreisachParams:
        rows = d["everett"]
        check_structure_size(len(rows) + 1, "levels (rows of everett + 1)", MAX_LEVELS)
        e = np.zeros((len(rows) + 1, len(rows) + 1))
        for i, row in enumerate(rows, start=1):
            if len(row) != i:
                raise ValueError(f"everett row {i} must have {i} values, got {len(row)}")
            e[i, :i] = row
        return cls(everett=e, offset=d["offset"])


@fill_doc
def everett(params: PreisachParams, alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Interpolated Everett function ``F(alpha, beta)`` (any shapes that broadcast, in [-1, 1]).

    Parameters
    ----------
    %(params)s
    alpha, beta : numpy.ndarray
        Switching-up and switching-down inputs in [-1, 1].

    Returns
    -------
    numpy.ndarray
        ``F(alpha, beta)``, the broadcast shape.
    """
    a_ext = antisymmetric(params.everett)
    scale = 0.5 * (params.levels - 1)
    xa, xb = ((np.asarray(v, dtype=float) + 1.0) * scale for v in (alpha, beta))
    ia = np.minimum(xa.astype(int), params.levels - 2)
    ib = np.minimum(xb.astype(int), params.levels - 2)
    sa, sb = xa - ia, xb - ib
    return ((1 - sa) * ((1 - sb) * a_ext[ia, ib] + sb * a_ext[ia, ib + 1])
            + sa * ((1 - sb) * a_ext[ia + 1, ib] + sb * a_ext[ia + 1, ib + 1]))
