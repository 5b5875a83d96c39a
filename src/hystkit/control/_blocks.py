"""Linear blocks of the position loop (ch. 7): moving mass, discrete PID, disturbance observer.

Every block is a frozen dataclass of physical parameters; the sample time belongs to the loop
(:class:`~hystkit.control.ControlLoop`), and each block is discretised for it on demand. Their
memory (plant position and velocity, PID integral, ...) is explicit loop state, never an
attribute.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._names import MASS

__all__ = [
    "DOCUMENT_PID_DIRECT",
    "DOCUMENT_PID_WEIGHTING",
    "MASS",
    "PID",
    "TS",
    "DisturbanceObserver",
    "Plant",
    "extended_input",
    "extended_matrices",
    "plant_matrices",
]

TS = 5.04e-4
"""Loop sample time [s], sec. 7.2 (derived from the filtered measurement data)."""



def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive number, got {value!r}")
    return value


@dataclass(frozen=True)
class Plant:
    """Moving mass ``P(s) = 1 / (m s^2)`` (eq. 7.1) with an optional actuator force limit.

    Parameters
    ----------
    mass : float
        Moving mass ``m`` [kg].
    u_max : float
        Actuator force limit [N]; the applied force is clipped to ``[-u_max, u_max]``.
        ``inf`` (default) is the document's unlimited actuator.
    """

    mass: float = MASS
    u_max: float = np.inf

    def __post_init__(self) -> None:
        _positive("mass", self.mass)
        if not (self.u_max > 0):
            raise ValueError(f"u_max must be positive (inf for no limit), got {self.u_max!r}")


def plant_matrices(mass: float, ts: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretisation of ``1 / (m s^2)``, state ``[position, velocity]``.

    The double integrator's matrix exponential is a finite series, so
    ``A = [[1, Ts], [0, 1]]``, ``B = [Ts^2 / (2 m), Ts / m]``, ``C = [1, 0]``, ``D = 0``; this
    is what ``scipy.signal.cont2discrete(..., method="zoh")`` returns, without round-off.

    Parameters
    ----------
    mass : float
        Moving mass ``m`` [kg].
    ts : float
        Sample time [s].

    Returns
    -------
    A : array, shape (2, 2)
        State matrix.
    B : array, shape (2,)
        Input vector (force [N] in).
    C : array, shape (2,)
        Output vector (position [m] out).

    Raises
    ------
    ValueError
        If `mass` or `ts` is not a positive number.
    """
    _positive("ts", ts)
    _positive("mass", mass)
    return (np.array([[1.0, ts], [0.0, 1.0]]), np.array([ts * ts / (2.0 * mass), ts / mass]),
            np.array([1.0, 0.0]))


@dataclass(frozen=True)
class PID:
    """Discrete PID of eq. 7.2, optionally with a filtered derivative and anti-windup.

    ``C(z) = Kp (1 + Ts / (Ti (z - 1)) + Td (z - 1) / (Ts z))`` (eq. 7.2): forward-Euler
    integral, backward-difference derivative. The document calls it a series PID; the formula is
    the ideal (parallel, common gain) form, which is what is implemented.

    Parameters
    ----------
    kp : float
        Proportional gain [N per unit of tracking error; N/m for both schemes here].
    ti : float
        Integral time [s]; ``inf`` removes the integral action.
    td : float
        Derivative time [s]; 0 removes the derivative action.
    tf : float
        Derivative filter time constant [s] (option). The derivative becomes
        ``Td s / (Tf s + 1)`` discretised by backward Euler,
        ``Td (z - 1) / ((Tf + Ts) z - Tf)``; 0 (default) is eq. 7.2 exactly.
    anti_windup : bool
        Conditional integration (clamping): while the actuator saturates
        (:attr:`Plant.u_max`) and the error drives further into saturation, the integral
        is frozen. No effect without a force limit.
    """

    kp: float
    ti: float = np.inf
    td: float = 0.0
    tf: float = 0.0
    anti_windup: bool = False

    def __post_init__(self) -> None:
        if not np.isfinite(self.kp):
            raise ValueError(f"kp must be finite, got {self.kp!r}")
        if not self.ti > 0:
            raise ValueError(f"ti must be positive (inf for no integral), got {self.ti!r}")
        for name in ("td", "tf"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a non-negative number, got {value!r}")

    def transfer_coefficients(self, ts: float) -> tuple[np.ndarray, np.ndarray]:
        """Numerator and denominator of ``C(z)`` in descending powers of ``z``.

        ``C = Kp [1 + Ts / (Ti (z - 1)) + Td (z - 1) / ((Tf + Ts) z - Tf)]`` over the common
        denominator ``(z - 1) ((Tf + Ts) z - Tf)``.
        """
        ki = ts / self.ti if np.isfinite(self.ti) else 0.0
        den_d = np.array([self.tf + ts, -self.tf])  # derivative's own denominator
        den = np.polymul([1.0, -1.0], den_d)
        num = den + np.r_[0.0, ki * den_d] + self.td * np.array([1.0, -2.0, 1.0])
        return self.kp * num, den


@dataclass(frozen=True)
class DisturbanceObserver:
    """Disturbance observer (DOB) of sec. 7.4 with a third-order binomial Q-filter.

    ``d_hat = Q (P_n^-1 y_hat - u)`` with ``P_n = 1 / (m_n s^2)`` and
    ``Q(s) = 1 / (tau s + 1)^3``, ``tau = 1 / (2 pi f_q)``; the applied force is
    ``u = u_pid - d_hat`` (fig. 7.18-7.19; the exposed scheme of the document's ref. [52],
    Schrijver & van Dijk 2002).

    Design procedure (documented in ``docs/control.md``):

    1. Nominal plant ``P_n`` = the plant model (mass ``m_n``).
    2. ``Q`` must have unit DC gain (a constant disturbance is removed) and relative degree
       >= 2 so that ``P_n^-1 Q`` is proper (realisable without differentiating the measured
       position twice). The binomial ``1 / (tau s + 1)^3`` meets both with a single tuning
       parameter and no overshoot in its step response. It is exactly the disturbance-estimate
       transfer of an extended-state observer of ``[position, velocity, input force]`` with all
       three poles at ``-1 / tau`` -- which is how it is implemented: in discrete time on the
       exact ZOH model, poles at ``z = exp(-Ts / tau)``, so ``P_n^-1`` is never formed and no
       mixed discretisation error arises (the discrete predictor matches ``Q`` in magnitude
       to 1e-4 up to ``f_q`` and adds one sample of delay).
    3. The bandwidth ``f_q`` is chosen by :func:`~hystkit.control.design_dob`: the largest
       candidate for which the *linearised* loop, sensor and compensator included, keeps the
       required margins. The sensor-compensator mismatch is the unmodelled dynamics that bound
       it, as the high-frequency plant dynamics do in ref. [52].

    Parameters
    ----------
    f_q : float
        Q-filter bandwidth ``1 / (2 pi tau)`` [Hz].
    nominal_mass : float, optional
        ``m_n`` [kg]; default: the plant's mass.
    """

    f_q: float
    nominal_mass: float | None = None

    def __post_init__(self) -> None:
        _positive("f_q", self.f_q)
        if self.nominal_mass is not None:
            _positive("nominal_mass", self.nominal_mass)

    def q_filter(self) -> tuple[np.ndarray, np.ndarray]:
        """Continuous ``Q(s)``: numerator and denominator, descending powers of ``s``."""
        tau = 1.0 / (2 * np.pi * self.f_q)
        return np.array([1.0]), np.polymul(np.polymul([tau, 1.0], [tau, 1.0]), [tau, 1.0])

    def observer_gain(self, mass: float, ts: float) -> np.ndarray:
        """Predictor gain ``L`` placing ``eig(A_e - L C_e)`` at ``exp(-Ts / tau)`` (triple).

        Extended model ``x_e = [p, v, d]``: ``p+ = p + Ts v + Ts^2/(2m)(u + d)``,
        ``v+ = v + Ts/m (u + d)``, ``d+ = d``; measurement ``p``. Ackermann's formula for the
        observable pair ``(A_e, C_e)``.
        """
        a, c = extended_matrices(mass, ts)
        z = np.exp(-2 * np.pi * self.f_q * ts)
        # Ackermann: L = phi(A) O^-1 [0, 0, 1]^T with phi(s) = (s - z)^3
        obs = np.vstack([c, c @ a, c @ a @ a])
        eye = np.eye(3)
        phi = (a - z * eye) @ (a - z * eye) @ (a - z * eye)
        return phi @ np.linalg.solve(obs, np.array([0.0, 0.0, 1.0]))


def extended_matrices(mass: float, ts: float) -> tuple[np.ndarray, np.ndarray]:
    """``A_e`` (3 x 3) and ``C_e`` (3,) of the plant extended with a constant input force."""
    a, b, c = plant_matrices(mass, ts)
    a_e = np.zeros((3, 3))
    a_e[:2, :2] = a
    a_e[:2, 2] = b
    a_e[2, 2] = 1.0
    return a_e, np.r_[c, 0.0]


def extended_input(mass: float, ts: float) -> np.ndarray:
    """``B_e`` (3,) of the extended model: the applied force enters like the disturbance."""
    _, b, _ = plant_matrices(mass, ts)
    return np.r_[b, 0.0]


DOCUMENT_PID_DIRECT = PID(kp=545.0, ti=0.029, td=0.0573)
"""Scheme (a) gains of sec. 7.2 (tuned for a 20 Hz crossover of the linear loop)."""

DOCUMENT_PID_WEIGHTING = PID(kp=16.76, ti=2.46, td=0.4619)
"""Scheme (b) gains of sec. 7.3 (crossover about 5 Hz)."""
