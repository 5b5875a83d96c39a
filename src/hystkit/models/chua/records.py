"""The Chua-Stromsmoe model's records: structure, parameters with their documented domain
(normalised units) and the output bound (the equations are in :mod:`.model`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._docs import docfiller
from .._protocol import Record
from .._validation import (
    check_cells,
    freeze_arrays,
)

fill_doc = docfiller("ChuaStructure", "ChuaParams")

_FIELDS = ("k0", "k_inf", "y_s", "g", "v_g", "delta")
MAX_ELEMENTS = 100  # O(N) a sample; the fit's Jacobian holds 6 N columns: 4.8 kB a sample
# Allowed range of each parameter (normalised units, eq. 5.10), wide around the fit's bounds
# (slopes and scales 1e-2 .. 1e2, G 1e-3 .. 100 / dt, V_g 1e-3 .. 1e3, delta 0 .. 1): within
# it the restoring function, its inverse and the limited sinh cannot overflow.
DOMAIN = {"k0": (1e-6, 1e6), "k_inf": (1e-6, 1e6), "y_s": (1e-6, 1e6), "g": (1e-9, 1e12),
          "v_g": (1e-6, 1e6), "delta": (0.0, 1e6)}


@dataclass(frozen=True)
class ChuaStructure(Record):
    """What does not get fitted.

    Parameters
    ----------
    n_elements : int
        Elements in series, ``1 <= N <= MAX_ELEMENTS`` (100: a sample costs O(N), the fit's
        finite-difference Jacobian holds ``6 N`` columns, 4.8 kB a sample, at the cap); 1 is
        eq. 2.3 itself.
    dt : float
        Sample time [s].
    slope_cap : float
        Largest allowed Euler slope ``dt g' f'`` (stable below 2; <= 1 gives no overshoot).
    """

    n_elements: int = 1
    dt: float = 0.025
    slope_cap: float = 1.0

    def __post_init__(self) -> None:
        # the cap first: nothing is allocated or looped over before it holds (inf, 1e12)
        if not (isinstance(self.n_elements, int | float) and self.n_elements <= MAX_ELEMENTS):
            raise ValueError(f"n_elements must be an integer in [1, {MAX_ELEMENTS}], got "
                             f"{self.n_elements!r}")
        check_cells(self.n_elements, self.dt, self.slope_cap, "n_elements")

    @property
    def n_params(self) -> int:
        return 6 * self.n_elements


@dataclass(frozen=True, eq=False)
class ChuaParams(Record):
    """Restoring and dissipation functions of each element, arrays of shape (N,).

    Parameters
    ----------
    k0, k_inf : array
        Slopes of ``f`` at 0 and far from 0 (> 0) [input units per output unit].
    y_s : array
        Output scale of the transition between the two slopes (> 0).
    g : array
        Slope ``G`` of ``g`` at the edge of its dead band (> 0) [output units per s per input
        unit].
    v_g : array
        Input scale of the sinh in ``g`` (> 0); large means linear.
    delta : array
        Half-width of the dead band of ``g`` (>= 0); 0 is the document's model.

    Notes
    -----
    The optimiser sees ``[log k0, log k_inf, log y_s, log g, log v_g, delta]`` per element.

    Domain (:data:`DOMAIN`): ``k_0, k_inf, y_s, V_g`` in ``[1e-6, 1e6]``, ``G`` in
    ``[1e-9, 1e12]``, ``delta`` in ``[0, 1e6]``. Within it every element stays within
    ``(max(|u|, |f(x0)|) + delta) / min(k_0, k_inf)`` of 0 (``slope_cap <= 1``: between
    ``f^-1(min u - delta)`` and ``f^-1(max u + delta)`` or its start), times
    ``s / (2 - s)`` for a slope cap ``s > 1`` (:func:`output_bound`). The inverse amplifies by ``1 / (dt g')``: it returns finite values
    or raises ``FitDivergedError``.
    """

    k0: np.ndarray
    k_inf: np.ndarray
    y_s: np.ndarray
    g: np.ndarray
    v_g: np.ndarray
    delta: np.ndarray
    n_elements: int = field(init=False)

    def __post_init__(self) -> None:
        n = np.size(self.k0)
        object.__setattr__(self, "n_elements", int(n))
        freeze_arrays(self, **dict.fromkeys(_FIELDS, n))
        for name in _FIELDS[:5]:
            if np.any(getattr(self, name) <= 0):
                raise ValueError(f"{name} must be positive (f and g strictly increasing, eq. 2.3)")
        if np.any(self.delta < 0):
            raise ValueError("delta (dead band of g) must be >= 0")
        for name, (low, high) in DOMAIN.items():
            values = getattr(self, name)
            bad = values[(values < low) | (values > high)]
            if bad.size:
                raise ValueError(f"{name} must lie in [{low:g}, {high:g}] (the domain where "
                                 f"runs stay bounded), got {float(bad[0]):g}")

    def to_vector(self) -> np.ndarray:
        cols = [np.log(getattr(self, name)) for name in _FIELDS[:5]] + [self.delta]
        return np.column_stack(cols).reshape(-1)

    @classmethod
    def from_vector(cls, theta: np.ndarray, n_elements: int) -> ChuaParams:
        t = np.asarray(theta, dtype=float).reshape(n_elements, 6)
        return cls(*np.exp(t[:, :5]).T, delta=t[:, 5])


@fill_doc
def output_bound(structure: ChuaStructure, params: ChuaParams, u_max: float) -> float:
    """``q sum_k (u_max + delta_k) / min(k_0, k_inf)_k`` with ``q = max(1, s / (2 - s))``,
    ``s`` the slope cap: no output of a run whose inputs, and the restoring forces
    ``f_k(x0_k)`` of its start, stay within ``u_max`` in magnitude exceeds it.

    Each element's band of equilibria lies within ``E_k = (u_max + delta_k) / min(k_0,
    k_inf)`` of 0 (``|f^-1(v)| <= |v| / min(k_0, k_inf)``), and a step multiplies the distance
    to it by ``1 - dt g' f'`` in ``[1 - s, 1]``: no overshoot for ``s <= 1``; beyond, an
    overshoot of at most ``s - 1`` times the distance, whose worst alternation settles at
    ``s E_k / (2 - s)``.

    Parameters
    ----------
    %(structure)s
    u_max : float
        Bound on the magnitude of the inputs and of the start's restoring forces.

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    q = max(1.0, structure.slope_cap / (2.0 - structure.slope_cap))
    return float(q * np.sum((u_max + params.delta) / np.minimum(params.k0, params.k_inf)))
