"""Classical Preisach model (sec. 2.1.1, eq. 2.1; appendix 9.3-9.5, eq. 9.1-9.13).

Relays ``gamma_ab`` (+1 once ``u >= alpha``, -1 once ``u <= beta``, unchanged in between) fill
the limiting triangle ``T = {-1 <= beta <= alpha <= 1}`` (data normalised to max |.| = 1,
eq. 5.10) with weight ``mu(alpha, beta) >= 0``. With the Everett function
``F(alpha, beta) = integral of mu over T(alpha, beta)`` (eq. 9.6) the output is (eq. 9.11-9.13)::

    y = -F(1, -1) + 2 * sum_{i=1}^{n-1} d_i F(max(s_i-1, s_i), min(s_i-1, s_i)) + y_0

where ``s_0 = -1, s_1, ..., s_n-1 = u(t)`` is the staircase of alternating dominant extrema
(the state) and ``d_i = +1`` on rising, ``-1`` on falling segments. Paired up this is eq. 9.13,
``2 sum_k [F(M_k, m_k-1) - F(M_k, m_k)]`` with ``m_0 = -1``; the last pair is
``2 [F(M_n, m_n-1) - F(M_n, u)]`` for a falling input (9.13 as printed) and ``2 F(u, m_n-1)``
for a rising one (``M_n = u``, and ``F(u, u) = 0``).

Typos of the document, fixed here: eq. 9.3 swaps its labels -- the printed ``f_1`` (ending in
``f_{M_n u} - f_{M_n m_n-1}``) is the *decreasing*-input output -- and its ``f_2`` is garbled;
with eq. 9.4 (``2 F(a, b) = f_a - f_ab``) the increasing-input output is
``-f+ + sum_{k<n} (f_{M_k m_k} - f_{M_k m_k-1}) + f_u - f_{u m_n-1}``. Eq. 9.1 writes
``Gamma mu(t)`` for ``Gamma u(t)``. The classical output is odd between the saturations
(``f- = -f+``); measured data are not, so an output offset ``y_0 = (f+ + f-) / 2`` is added.

Discretisation. ``F`` is stored at the nodes of ``L`` equally spaced levels ``h_i`` (the size
knob), ``E[i, j] = F(h_i, h_j)`` for ``i > j``, and interpolated bilinearly after extending it
antisymmetrically (``F(b, a) := -F(a, b)``), which keeps the interpolant zero on the diagonal:
on a diagonal square it reduces to ``E[i+1, i] (s - t)``. The interpolant is itself the
Everett function of a Preisach weight -- a uniform density of mass
``E[i+1, j] - E[i+1, j+1] - E[i, j] + E[i, j+1]`` on each off-diagonal grid square and mass
``E[i+1, i]`` spread along each diagonal segment (zero-width relays) -- so the output is
continuous, piecewise linear along a branch, and non-negative masses give monotone branches.

Beyond [-1, 1] every relay is saturated; the model continues as the straight line of slope
``F(1, -1)`` (the major loop's mean slope), so compensators do not flatten outside the fitting
range and the inverse exists for every output.

State: the staircase ``x = [-1, s_1, ..., s_n-1]`` (clipped inputs). ``x0=None`` is the
demagnetised state (AC-demagnetised: ``S+ = {alpha + beta < 0}``, drawn as a staircase of
``L - 1`` steps); ``[-1]`` is negative saturation. A new extremum wipes out every earlier one it
reaches. The kernels keep it in a buffer of ``capacity`` entries; when it is about to fill, the
innermost closed loop is forgotten (an output change of twice the weight inside that loop's
rectangle, small because nested loops shrink).

Loop state. The family protocol needs a state of fixed length, so ``FAMILY`` (``family.py``)
and the compiled loop block store the staircase *packed*: ``[n, s_0, .., s_{n-1}, 0, ..]``,
``capacity + 1`` floats (:func:`pack_state`). The functions of this module take and return the
plain staircase.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import FitDivergedError
from .._protocol import Record
from .._validation import (
    check_dt,
    check_finite_run,
    check_magnitude,
    check_signal,
    check_size,
    check_structure_size,
    run_steps,
)
from . import kernels

__all__ = [
    "MAX_CAPACITY",
    "MAX_LEVELS",
    "MAX_VALUE",
    "MIN_RISE",
    "PreisachParams",
    "PreisachStructure",
    "antisymmetric",
    "cell_regressors",
    "check_rise",
    "check_state",
    "demagnetised_state",
    "everett",
    "everett_from_masses",
    "grid",
    "invert",
    "invert_step",
    "kernel_parts",
    "masses_from_everett",
    "output_bound",
    "pack_state",
    "prepare_run",
    "simulate",
    "simulate_reference",
    "staircase_terms",
    "step",
    "unpack_state",
    "update_staircase",
]

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


def masses_from_everett(e: np.ndarray) -> np.ndarray:
    """Inverse of :func:`everett_from_masses`: mixed second differences of ``E``.

    Parameters
    ----------
    e : numpy.ndarray, shape (L, L)
        Everett nodes (lower triangle).

    Returns
    -------
    numpy.ndarray, shape (L - 1, L - 1)
        Cell masses, lower triangle including the diagonal.
    """
    e = np.tril(np.asarray(e, dtype=float), -1)
    m = e[1:, :-1] - e[1:, 1:] - e[:-1, :-1] + e[:-1, 1:]
    return np.tril(m)


def antisymmetric(e: np.ndarray) -> np.ndarray:
    """``E - E^T``: the extension the bilinear interpolation runs on (zero diagonal).

    Parameters
    ----------
    e : numpy.ndarray, shape (L, L)
        Everett nodes (lower triangle).

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


def everett(params: PreisachParams, alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Interpolated Everett function ``F(alpha, beta)`` (any shapes that broadcast, in [-1, 1]).

    Parameters
    ----------
    params : PreisachParams
        The model's parameters.
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


def demagnetised_state(n_steps: int) -> np.ndarray:
    """Staircase of the demagnetised state ``S+ = {alpha + beta < 0}``, ``n_steps`` steps.

    Minima ``m_k = -1 + k / K``, maxima ``M_k = -(m_k-1 + m_k) / 2`` (the line at each step's
    midpoint), ending at the input 0; shape (2 K + 1,).

    Parameters
    ----------
    n_steps : int
        Steps ``K``.

    Returns
    -------
    numpy.ndarray, shape (2 K + 1,)
        The staircase.
    """
    k = np.arange(1, n_steps + 1)
    x = np.empty(2 * n_steps + 1)
    x[0::2] = -1.0 + np.arange(n_steps + 1) / n_steps
    x[1::2] = 1.0 - (k - 0.5) / n_steps
    return x


def check_state(x: np.ndarray, capacity: int) -> np.ndarray:
    """Validate a staircase: starts at -1, inside [-1, 1], alternating, strictly nested.

    Parameters
    ----------
    x : numpy.ndarray
        The staircase.
    capacity : int
        Largest number of entries.

    Returns
    -------
    numpy.ndarray
        `x` as a contiguous float array.

    Raises
    ------
    ValueError
        A staircase that breaks any of these rules.
    """
    x = np.ascontiguousarray(x, dtype=float)
    if x.ndim != 1 or not 1 <= x.size <= capacity:
        raise ValueError(f"the state must be a 1-D staircase of 1..{capacity} values, got shape "
                         f"{x.shape}")
    if not np.all(np.isfinite(x)) or x[0] != -1.0 or np.any(np.abs(x) > 1):
        raise ValueError("the state must be finite, inside [-1, 1] and start at -1")
    steps = np.diff(x)  # their signs are exact, their lengths round
    # nesting compared on the values, as the wiping rule does: a kept extremum one ulp inside
    # the older one can have a step length that rounds to the older step's
    if np.any(steps[0::2] <= 0) or np.any(steps[1::2] >= 0) or np.any(
            x[2::2] <= x[0:-2:2]) or np.any(x[3::2] >= x[1:-2:2]):
        raise ValueError("the state must alternate rising/falling with shrinking steps "
                         "(a staircase of dominant extrema)")
    return x


def update_staircase(x: np.ndarray, u: float, capacity: int) -> np.ndarray:
    """Apply one input to the staircase (reference of the kernel's rule, wiping-out included).

    If a push could fill the buffer (``capacity - 1`` entries), the innermost closed loop is
    forgotten first. Then a move in the direction of the last segment replaces the last entry,
    a reversal appends one, and each earlier extremum the input reaches or passes is erased
    with the reversal that followed it.

    Parameters
    ----------
    x : numpy.ndarray
        Staircase before the input.
    u : float
        The input; clipped to [-1, 1].
    capacity : int
        Staircase buffer size.

    Returns
    -------
    numpy.ndarray
        Staircase after the input.
    """
    s = list(x)
    if len(s) >= capacity - 1:
        del s[-3:-1]
    u = min(1.0, max(-1.0, float(u)))
    if u == s[-1]:
        return np.array(s)
    if len(s) == 1 or (u > s[-1]) != (s[-1] > s[-2]):
        s.append(u)
    else:
        s[-1] = u
    while len(s) >= 3 and (s[-1] - s[-3]) * (s[-1] - s[-2]) >= 0:
        del s[-3:-1]
    return np.array(s)


def pack_state(x: np.ndarray, capacity: int) -> np.ndarray:
    """Staircase -> fixed-length state ``[n, s_0 .. s_{n-1}, 0 ..]``, shape (capacity + 1,).

    Parameters
    ----------
    x : numpy.ndarray
        The staircase.
    capacity : int
        Staircase buffer size.

    Returns
    -------
    numpy.ndarray, shape (capacity + 1,)
        The packed state.

    Raises
    ------
    ValueError
        A staircase longer than `capacity`.
    """
    x = np.asarray(x, dtype=float)
    if not 1 <= x.size <= capacity:
        raise ValueError(f"a staircase of {x.size} values does not fit capacity {capacity}")
    packed = np.zeros(capacity + 1)
    packed[0] = x.size
    packed[1:1 + x.size] = x
    return packed


def unpack_state(packed: np.ndarray, capacity: int) -> np.ndarray:
    """Inverse of :func:`pack_state` (the count is rounded, so a float count is safe).

    Parameters
    ----------
    packed : numpy.ndarray, shape (capacity + 1,)
        The packed state.
    capacity : int
        Staircase buffer size.

    Returns
    -------
    numpy.ndarray
        The staircase.

    Raises
    ------
    ValueError
        A wrong shape or count.
    """
    packed = np.asarray(packed, dtype=float)
    if packed.shape != (capacity + 1,):
        raise ValueError(f"the packed Preisach state has shape ({capacity + 1},) = (capacity "
                         f"+ 1,), got {packed.shape}")
    n = int(np.rint(packed[0])) if np.isfinite(packed[0]) else -1
    if not 1 <= n <= capacity:
        raise ValueError(f"the packed state's length {packed[0]!r} is not in 1..{capacity}")
    return packed[1:1 + n].copy()


def staircase_terms(e: np.ndarray, x: np.ndarray) -> float:
    """Relay part of eq. 9.13 for Everett nodes ``e`` and staircase ``x`` (plain sum).

    Parameters
    ----------
    e : numpy.ndarray, shape (L, L)
        Everett nodes (lower triangle).
    x : numpy.ndarray
        The staircase.

    Returns
    -------
    float
        The relay part of the output.
    """
    probe = PreisachParams(everett=e)
    hi, lo = np.maximum(x[:-1], x[1:]), np.minimum(x[:-1], x[1:])
    signs = np.where(x[1:] >= x[:-1], 1.0, -1.0)
    return float(-e[-1, 0] + 2.0 * np.sum(signs * everett(probe, hi, lo)))


def _slope(params: PreisachParams) -> float:
    return float(params.everett[-1, 0])


def kernel_parts(params: PreisachParams) -> tuple[np.ndarray, bool, np.ndarray, float]:
    """What the compiled kernels run on: tables (1, L, L), weighted (False), output polynomial
    (the offset) and the slope of the straight-line extension.

    Parameters
    ----------
    params : PreisachParams
        The model's parameters.

    Returns
    -------
    tables : numpy.ndarray, shape (1, L, L)
        The antisymmetric Everett table.
    weighted : bool
        False: no input-dependent weight.
    poly : numpy.ndarray, shape (1,)
        The output offset.
    slope : float
        Slope of the straight-line extension.
    """
    return (antisymmetric(params.everett)[None], False, np.array([params.offset]),
            _slope(params))


def step(structure: PreisachStructure, params: PreisachParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample: update the staircase with ``u``, then the output (eq. 9.13 + extension).

    Parameters
    ----------
    structure : PreisachStructure
        The model's structure.
    params : PreisachParams
        Its parameters.
    x : numpy.ndarray, shape (k,)
        Staircase before the sample.
    u : float
        Normalised input of the sample.

    Returns
    -------
    y : float
    x_next : array, shape (k,)
        Staircase after the sample.
    """
    x_next = update_staircase(x, u, structure.capacity)
    u_clip = x_next[-1]
    y = staircase_terms(params.everett, x_next) + params.offset + _slope(params) * (u - u_clip)
    return y, x_next


def _check(structure: PreisachStructure, params: PreisachParams, v: np.ndarray, name: str,
           x0: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    check_size(params.levels, structure.levels, "levels")
    return prepare_run(structure, v, name, x0)


def prepare_run(structure, v: np.ndarray, name: str,
                x0: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Checked input and start state (demagnetised if ``x0`` is None) for a staircase model.

    Shared with the generalised model, whose structure has the same ``levels`` and
    ``capacity``.

    Parameters
    ----------
    structure : PreisachStructure or GPreisachStructure
        Gives ``levels`` and ``capacity``.
    v : numpy.ndarray, shape (n,)
        Input (or output, for an inverse run).
    name : str
        Its name in error messages.
    x0 : numpy.ndarray, optional
        Initial staircase; None is the demagnetised state.

    Returns
    -------
    v : numpy.ndarray, shape (n,)
        The checked signal.
    x : numpy.ndarray
        The checked start staircase.
    """
    v = check_signal(v, name)
    x = demagnetised_state(structure.levels - 1) if x0 is None else x0
    return v, check_state(x, structure.capacity)


def simulate(structure: PreisachStructure, params: PreisachParams, u: np.ndarray,
             x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the model over an input sequence (compiled kernel, amortised O(1) per sample).

    Parameters
    ----------
    structure : PreisachStructure
        The model's structure.
    params : PreisachParams
        Its parameters.
    u : array, shape (n,)
        Normalised input; values beyond [-1, 1] follow the straight-line extension.
    x0 : array, shape (k,), or None
        Initial staircase; ``None`` is the demagnetised state, ``[-1.0]`` negative saturation.

    Returns
    -------
    y : array, shape (n,)
    x_end : array, shape (k',)
        Final staircase; passing it as ``x0`` continues the run exactly.
    """
    u, x = _check(structure, params, u, "u", x0)
    tables = antisymmetric(params.everett)[None]
    relay, x_end = kernels.run_tables(u, x, tables, structure.capacity)
    u_clip = np.clip(u, -1.0, 1.0)
    with np.errstate(over="ignore", invalid="ignore"):  # inputs near 1e308 on the extension
        y = relay[:, 0] + params.offset + _slope(params) * (u - u_clip)
    return check_finite_run(y, "preisach"), x_end


def simulate_reference(structure: PreisachStructure, params: PreisachParams, u: np.ndarray,
                       x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Same as :func:`simulate`, as a plain loop over :func:`step` (the readable reference).

    Parameters
    ----------
    structure : PreisachStructure
        The model's structure.
    params : PreisachParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Input, one value per sample.
    x0 : numpy.ndarray, optional
        Initial staircase; None is the demagnetised state.

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Output.
    x_end : numpy.ndarray
        State after the last sample.
    """
    u, x = _check(structure, params, u, "u", x0)
    return run_steps(step, structure, params, u, x)


def invert(structure: PreisachStructure, params: PreisachParams, y: np.ndarray,
           x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Input that reproduces an output sequence, by monotone search (bisection) per sample.

    From the present state the branch ``y(u)`` is monotone (non-decreasing in ``u``) when the
    cell masses are non-negative; its side of the present output picks the rising or falling
    branch and bisection on ``u`` in [-1, 1] finds the input that is closest to the present one
    (to ``INVERT_TOL``, then one exact linear step inside the piecewise-linear branch). Outputs
    beyond the saturated ones are inverted on the straight-line extension. The state is then
    updated with the found input. For weights of mixed sign the branch may fold; bisection
    still returns an input that reproduces the output (the branch is continuous).

    Parameters
    ----------
    structure : PreisachStructure
        The model's structure.
    params : PreisachParams
        Its parameters.
    y : array, shape (n,)
    x0 : array or None
        Initial staircase, as in :func:`simulate`.

    Returns
    -------
    u_hat : array, shape (n,)
    x_end : array

    Raises
    ------
    FitDivergedError
        If ``F(1, -1) <= 0``: the major loop does not rise, so no inverse exists.
    """
    y, x = _check(structure, params, y, "y", x0)
    check_rise(_slope(params), np.abs(params.masses()).sum(), "Preisach")
    tables, weighted, poly, slope = kernel_parts(params)
    u_hat, x_end = kernels.invert(y, x, tables, weighted, poly, slope, structure.capacity,
                                  INVERT_TOL)
    return check_finite_run(u_hat, "inverse Preisach", "input estimate"), x_end


def check_rise(rise: float, mass: float, model: str) -> None:
    """Raise FitDivergedError unless the major loop rises by at least ``MIN_RISE`` of the
    total mass: the inverse continues beyond saturation with slope ``1 / rise``.

    Parameters
    ----------
    rise : float
        Rise of the major loop, ``F(1, -1)``.
    mass : float
        Total absolute mass of the weights.
    model : str
        Model name for the message.

    Raises
    ------
    FitDivergedError
        The major loop does not rise enough.
    """
    if not rise >= MIN_RISE * max(mass, 1e-300):
        raise FitDivergedError(f"the {model} model's major loop does not rise (rise {rise:.4g} "
                               f"for a total mass {mass:.4g}, at least {MIN_RISE:g} of it is "
                               f"needed); it has no inverse")


def output_bound(params: PreisachParams, u_max: float) -> float:
    """``|y_0| + sum |m| max(1, u_max)``: no output of a run with ``|u| <= u_max`` exceeds it
    (each cell contributes at most ``|m|``; beyond [-1, 1] the line of slope ``F(1, -1)``).

    Parameters
    ----------
    params : PreisachParams
        The model's parameters.
    u_max : float
        Largest input magnitude.

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    return float(abs(params.offset) + np.abs(params.masses()).sum() * max(1.0, u_max))


def invert_step(structure: PreisachStructure, params: PreisachParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of :func:`invert` from the staircase ``x``: ``(u_hat, x_next)``.

    Parameters
    ----------
    structure : PreisachStructure
        The model's structure.
    params : PreisachParams
        Its parameters.
    x : numpy.ndarray, shape (k,)
        Staircase before the sample.
    y : float
        Output to reach at this sample.

    Returns
    -------
    u : float
        Input that gives `y` from the present state.
    x_next : numpy.ndarray
        State after the sample.
    """
    u_hat, x_next = invert(structure, params, np.array([float(y)]), x0=x)
    return float(u_hat[0]), x_next


def cell_regressors(levels: int, u: np.ndarray, x0: np.ndarray | None = None,
                    capacity: int = 1024) -> np.ndarray:
    """Relay output of each unit-mass cell: the model is ``Phi @ masses.flat + offset``.

    Columns follow the lower triangle (incl. diagonal) of the (L-1, L-1) mass array in row
    order (``np.tril_indices(L - 1)``); entry ``2 * (fraction of the cell's mass switched
    up) - 1``, computed by the same staircase kernel as the model. Inputs outside [-1, 1]
    are clipped: the straight-line extension is not part of ``Phi``.

    Parameters
    ----------
    levels : int
        Grid levels ``L``.
    u : numpy.ndarray, shape (n,)
        Normalised input.
    x0 : numpy.ndarray, optional
        Initial staircase; None is the demagnetised state.
    capacity : int, default 1024
        Staircase buffer size.

    Returns
    -------
    array, shape (n, L (L - 1) / 2)
    """
    rows, cols = np.tril_indices(levels - 1)
    units = np.zeros((rows.size, levels - 1, levels - 1))
    units[np.arange(rows.size), rows, cols] = 1.0
    tables = np.stack([antisymmetric(everett_from_masses(m)) for m in units])
    x = demagnetised_state(levels - 1) if x0 is None else check_state(x0, capacity)
    phi, _ = kernels.run_tables(np.ascontiguousarray(u, dtype=float), x, tables, capacity)
    return phi
