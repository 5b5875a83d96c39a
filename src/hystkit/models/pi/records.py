"""The Prandtl-Ishlinskii model's records: structure and parameters with their sizes and
documented domain (normalised units), and the output bound (the operators are in
:mod:`.operators`, the model in :mod:`.model`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._protocol import Record
from .._validation import (
    check_dt,
    finite_floats,
    freeze_arrays,
    frozen_array,
)

# Sizes: a sample costs O(plays + dead zones + creep operators); the fit's regressor matrix
# holds n_play + 2 n_creep + 2 n_deadzone + 1 columns, 10 kB a sample at the caps.
MAX_PLAYS = 1000
MAX_DEADZONES = 100  # per side
MAX_CREEP = 20
MAX_VALUE = 1e6  # weights, thresholds and |b| in normalised units (fit: slopes <= ~100)
INVERSE_MIN_SLOPE = 1 / MAX_VALUE  # smallest slope partial sum with an inverse (fit: >= 0.01)


def _check_count(values, maximum: int, name: str) -> None:
    """Refuse more than ``maximum`` values before any array is built from them."""
    if np.ndim(values) > 0 and len(values) > maximum:
        raise ValueError(f"{name} may hold at most {maximum} values, got {len(values)}")


def _check_magnitude(values, name: str) -> None:
    if np.any(np.abs(values) > MAX_VALUE):
        raise ValueError(f"{name} must be at most {MAX_VALUE:g} in magnitude (the domain where "
                         f"runs stay bounded), got {float(np.max(np.abs(values))):g}")


def _float_tuple(values, name: str) -> tuple[float, ...]:
    return tuple(frozen_array(values, None, name).tolist())


@dataclass(frozen=True)
class PiStructure(Record):
    """What does not get fitted: operator thresholds, creep eigenvalues and the sample time.

    Parameters
    ----------
    play_thresholds : tuple of float
        ``r_0 = 0 < r_1 < ... <= MAX_VALUE`` in input units (eq. 2.11); their number is the
        model size, at most ``MAX_PLAYS`` (1000).
    n_deadzone : int
        One-sided dead-zone operators on *each* side of ``d = 0`` (eq. 2.12), at most
        ``MAX_DEADZONES`` (100); 0 makes ``S`` linear. Their thresholds are fitted (they follow from the output range), so they live
        in :class:`PiParams`.
    creep_rates : tuple of float
        Eigenvalues ``a_j`` [1/s] of the linear creep operators (eq. 2.14), at most
        ``MAX_CREEP`` (20); empty for the rate-independent model. At the size caps a sample
        costs about 1300 operator updates and the fit's regressors 10 kB.
    dt : float
        Sample time [s]. The plays are rate independent; the creep operators are not, and
        their per-sample gains :attr:`creep_gains` follow from the rates and ``dt``, so the
        same structure at another ``dt`` is the same continuous-time model.
    """

    play_thresholds: tuple[float, ...] = (0.0,)
    n_deadzone: int = 0
    creep_rates: tuple[float, ...] = ()
    dt: float = 0.025

    def __post_init__(self) -> None:
        _check_count(self.play_thresholds, MAX_PLAYS, "play_thresholds")
        _check_count(self.creep_rates, MAX_CREEP, "creep_rates")
        if not (isinstance(self.n_deadzone, int | float) and self.n_deadzone <= MAX_DEADZONES):
            raise ValueError(f"n_deadzone must be an integer in [0, {MAX_DEADZONES}], got "
                             f"{self.n_deadzone!r}")
        r = _float_tuple(self.play_thresholds, "play_thresholds")
        _check_magnitude(r, "play_thresholds")
        object.__setattr__(self, "play_thresholds", r)
        if r[0] != 0.0 or np.any(np.diff(r) <= 0):
            raise ValueError(f"play_thresholds must start at 0 and increase strictly, got {r}")
        rates = _float_tuple(self.creep_rates, "creep_rates")
        object.__setattr__(self, "creep_rates", rates)
        if any(a <= 0 for a in rates):
            raise ValueError(f"creep_rates must be positive eigenvalues [1/s], got {rates}")
        if int(self.n_deadzone) != self.n_deadzone or self.n_deadzone < 0:
            raise ValueError(f"n_deadzone must be a non-negative integer, got {self.n_deadzone!r}")
        check_dt(self.dt)

    @property
    def n_play(self) -> int:
        return len(self.play_thresholds)

    @property
    def n_creep(self) -> int:
        return len(self.creep_rates)

    @property
    def creep_gains(self) -> np.ndarray:
        """``c_j = 1 - exp(-a_j dt)``: the fraction of the gap a creep state closes per sample."""
        return -np.expm1(-np.asarray(self.creep_rates, dtype=float) * self.dt)


@dataclass(frozen=True, eq=False)
class PiParams(Record):
    """Fitted quantities of a modified PI model.

    Parameters
    ----------
    w_h : array, shape (n_play,)
        Play weights ``w_H`` (eq. 2.7).
    w_s : array, shape (2 n_deadzone + 1,)
        Dead-zone weights ``w_S`` (eq. 2.12); the middle one belongs to ``d = 0``.
    d_s : array, shape (2 n_deadzone + 1,)
        Dead-zone thresholds ``d_-m < .. < d_0 = 0 < .. < d_m`` in units of ``H + K + b``.
    w_k : array, shape (n_creep,)
        Creep weights ``w_K`` (eq. 2.14).
    b : float
        Offset inside ``S``.

    Notes
    -----
    Domain: every weight, threshold and ``|b|`` at most ``MAX_VALUE`` (1e6, normalised units;
    the fit's slopes are at most ~100). Plays and creep states stay within ``M = max(|u|,
    |x0|)`` and ``|S_d(v)| <= |v|``, so ``|y| <= sum |w_S| ((sum |w_H| + sum |w_K|) M + |b|)``
    (:func:`output_bound`). The inverse returns finite values or raises ``FitDivergedError``.
    """

    w_h: np.ndarray
    w_s: np.ndarray = (1.0,)
    d_s: np.ndarray = (0.0,)
    w_k: np.ndarray = ()
    b: float = 0.0
    n_play: int = field(init=False)
    n_deadzone: int = field(init=False)
    n_creep: int = field(init=False)

    def __post_init__(self) -> None:
        _check_count(self.w_h, MAX_PLAYS, "w_h")
        _check_count(self.w_s, 2 * MAX_DEADZONES + 1, "w_s")
        _check_count(self.w_k, MAX_CREEP, "w_k")
        freeze_arrays(self, w_h=None, w_s=None)
        freeze_arrays(self, d_s=self.w_s.size, w_k=None)
        finite_floats(self, "b")
        for name in ("w_h", "w_s", "d_s", "w_k", "b"):
            _check_magnitude(getattr(self, name), name)
        m = (self.d_s.size - 1) // 2
        if self.w_h.size < 1 or self.d_s.size % 2 == 0 or self.d_s[m] != 0.0 \
                or np.any(np.diff(self.d_s) <= 0):
            raise ValueError(f"need at least one play weight, and dead-zone thresholds that "
                             f"increase strictly with 0 in the middle (eq. 2.12), got w_h "
                             f"{self.w_h.tolist()}, d_s {self.d_s.tolist()}")
        object.__setattr__(self, "n_play", int(self.w_h.size))
        object.__setattr__(self, "n_deadzone", int(m))
        object.__setattr__(self, "n_creep", int(self.w_k.size))

    def to_dict(self) -> dict:
        """Record's dict, with the centre threshold ``d_0 = 0`` written as the integer 0: it is
        structural, not fitted, and generic parameter vectors keep integers fixed
        (``compensation._param_vector``). Same keys and values as before (``0 == 0.0``)."""
        d = super().to_dict()
        d["d_s"][self.n_deadzone] = 0
        return d


def output_bound(params: PiParams, u_max: float) -> float:
    """``sum |w_S| ((sum |w_H| + sum |w_K|) u_max + |b|)``: no output of a run whose inputs
    and initial states stay within ``u_max`` in magnitude exceeds it.

    Parameters
    ----------
    params : PiParams
        Its parameters.
    u_max : float
        Bound on the magnitude of the inputs and the initial states.

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    inner = (np.abs(params.w_h).sum() + np.abs(params.w_k).sum()) * u_max + abs(params.b)
    return float(np.abs(params.w_s).sum() * inner)
