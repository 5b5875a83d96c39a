"""The Preisach staircase: the model's memory of alternating input extrema, its update, its
packing into a fixed-size float vector (the protocol's state) and the start of a run. Shared
with the generalised model (:mod:`hystkit.models.gpreisach`).
"""

from __future__ import annotations

import numpy as np

from .._validation import check_signal
from .records import (
    PreisachParams,
    everett,
)


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
    return v, start_staircase(structure, None, x0, v[0], False)


def start_staircase(structure, params, x0: np.ndarray | None, value: float,
                    inverse: bool) -> np.ndarray:
    """The checked start staircase of a run: demagnetised if ``x0`` is None (the first sample
    then moves it to the first input), else ``x0`` (``Runs.start`` of the staircase models).

    Parameters
    ----------
    structure : PreisachStructure or GPreisachStructure
        Gives ``levels`` and ``capacity``.
    params : PreisachParams or GPreisachParams or None
        Not used: the start does not depend on them.
    x0 : numpy.ndarray or None
        Initial staircase.
    value : float
        First sample of the run (not used: a staircase starts demagnetised).
    inverse : bool
        Whether the run is an inverse one (not used).

    Returns
    -------
    numpy.ndarray
        The start staircase.
    """
    x = demagnetised_state(structure.levels - 1) if x0 is None else x0
    return check_state(x, structure.capacity)
