"""The Bouc-Wen oscillator's records: structure (sample time, RK4 substeps, input hold, start)
and parameters with their domain, and the parameters of the Bouc-Wen hysteretic benchmark
(the equations and runs are in :mod:`.model`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._protocol import Record
from .._validation import check_dt

HOLDS = ("linear", "zoh")
STARTS = ("rest", "equilibrium")
MAX_SUBSTEPS = 2048  # RK4 steps a sample; the cost at the cap is in BoucWenStructure
MAX_NU = 8.0  # the fit's nu is <= 4; beyond 8, |z|^nu overflows for |z| > 1e38
RK4_LIMIT = 2.785  # RK4 is stable on the imaginary axis up to |lambda h| = 2 sqrt(2)


@dataclass(frozen=True)
class BoucWenStructure(Record):
    """What does not get fitted: sample time, RK4 substeps, force between samples, start.

    Parameters
    ----------
    dt : float
        Sample time of the input and output sequences [s].
    substeps : int
        RK4 steps per sample, ``1 <= substeps <= MAX_SUBSTEPS`` (2048: 57 ns a step, 0.12 ms a
        sample, 2 min for a million samples at ``nu = 1``, 4x that otherwise; no memory);
        the integration step is ``dt / substeps``.
    input_hold : {"linear", "zoh"}
        Force between samples: linear interpolation (first-order hold) or zero-order hold.
    start : {"rest", "equilibrium"}
        State at the first sample when a run gets no ``x0`` (module docstring).
    """

    dt: float = 0.025
    substeps: int = 4
    input_hold: str = "linear"
    start: str = "rest"

    def __post_init__(self) -> None:
        check_dt(self.dt)
        # Checked before anything loops over it: a model file may say 1e12 (or inf).
        try:
            whole = int(self.substeps) == self.substeps
        except (TypeError, ValueError, OverflowError):
            whole = False
        if not whole or not 1 <= self.substeps <= MAX_SUBSTEPS:
            raise ValueError(f"substeps must be an integer in [1, {MAX_SUBSTEPS}], "
                             f"got {self.substeps!r}")
        object.__setattr__(self, "substeps", int(self.substeps))
        if self.input_hold not in HOLDS:
            raise ValueError(f"input_hold must be one of {HOLDS}, got {self.input_hold!r}")
        if self.start not in STARTS:
            raise ValueError(f"start must be one of {STARTS}, got {self.start!r}")

    @property
    def step_size(self) -> float:
        """RK4 step ``h = dt / substeps`` [s]."""
        return self.dt / self.substeps


@dataclass(frozen=True)
class BoucWenParams(Record):
    """Physical parameters of the oscillator (module docstring for the equations).

    Parameters
    ----------
    m, c, k : float
        Mass, viscous damping and linear stiffness (> 0); on the benchmark kg, N s/m, N/m.
    alpha : float
        Initial stiffness of the hysteretic element (> 0) [N/m].
    beta, gamma : float
        Shape of the hysteresis (any sign) [m^-1 N^(1 - nu)].
    nu : float
        Sharpness of the transition, ``1 <= nu <= MAX_NU`` (8): ``>= 1`` keeps the right-hand
        side Lipschitz, the cap keeps ``|z|^nu`` finite for ``|z| < 1e38`` (the fit's nu is at
        most 4).

    Notes
    -----
    The optimiser works on :meth:`to_vector`: ``[log K0, log w0, log zeta, logit r,
    beta + gamma, beta - gamma, nu]`` with the initial stiffness ``K0 = k + alpha``, the
    undamped natural frequency ``w0 = sqrt(K0 / m)``, the damping ratio
    ``zeta = c / (2 sqrt(K0 m))`` and the hysteretic share ``r = alpha / K0``. ``K0`` sets the
    small-signal gain and ``w0`` the integration stability (``w0 h`` must stay small), so they
    get their own bounds; the log and the logit keep ``m, c, k, alpha`` positive.
    ``beta + gamma`` and ``beta - gamma`` set the element's tangent stiffness on loading
    (``y' z > 0``: ``dz/dy = alpha - (beta + gamma) |z|^nu``) and on unloading (``y' z < 0``:
    ``dz/dy = alpha + (beta - gamma) |z|^nu``). Both non-negative is the class whose ``z`` stays
    bounded (``|z| <= (alpha / (beta + gamma))^(1/nu)`` from rest) and whose loops dissipate
    (clockwise in the z-y plane); Ismail et al. 2009, sec. 3.
    """

    m: float
    c: float
    k: float
    alpha: float
    beta: float
    gamma: float
    nu: float = 1.0

    def __post_init__(self) -> None:
        for name in ("m", "c", "k", "alpha", "beta", "gamma", "nu"):
            value = getattr(self, name)
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"{name} must be a number, got {value!r}") from None
            if not np.isfinite(value):
                raise ValueError(f"{name} must be finite, got {value}")
            object.__setattr__(self, name, value)
        for name in ("m", "c", "k", "alpha"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be positive, got {getattr(self, name)}")
        if not np.isfinite(1.0 / self.m):  # the kernel runs on 1 / m (a subnormal m: inf)
            raise ValueError(f"m must be at least {1 / np.finfo(float).max:.3g}, got {self.m}")
        if not 1 <= self.nu <= MAX_NU:
            raise ValueError(f"nu must lie in [1, {MAX_NU:g}], got {self.nu}")

    @classmethod
    def from_benchmark(cls, m: float, c: float, k: float, alpha: float, beta: float,
                       gamma: float, delta: float, nu: float) -> BoucWenParams:
        """Parameters in the benchmark's notation (``z' = alpha y' - beta (gamma ... + delta
        ...)``), mapped to ``beta = beta_b gamma_b``, ``gamma = beta_b delta_b``."""
        return cls(m=m, c=c, k=k, alpha=alpha, beta=beta * gamma, gamma=beta * delta, nu=nu)

    @property
    def k0(self) -> float:
        """Initial stiffness ``k + alpha`` (the small-signal stiffness at ``z = 0``)."""
        return self.k + self.alpha

    @property
    def omega0(self) -> float:
        """Undamped natural frequency at the initial stiffness [rad/s]."""
        return float(np.sqrt(self.k0 / self.m))

    @property
    def zeta(self) -> float:
        """Damping ratio at the initial stiffness."""
        return self.c / (2.0 * np.sqrt(self.k0 * self.m))

    def as_array(self) -> np.ndarray:
        """``(m, c, k, alpha, beta, gamma, nu)``, the kernels' order."""
        return np.array([self.m, self.c, self.k, self.alpha, self.beta, self.gamma, self.nu])

    def to_vector(self) -> np.ndarray:
        """Optimiser coordinates (see Notes of the class)."""
        r = self.alpha / self.k0
        return np.array([np.log(self.k0), np.log(self.omega0), np.log(self.zeta),
                         np.log(r / (1.0 - r)), self.beta + self.gamma, self.beta - self.gamma,
                         self.nu])

    @classmethod
    def from_vector(cls, theta: np.ndarray) -> BoucWenParams:
        """Inverse of :meth:`to_vector`."""
        log_k0, log_w0, log_zeta, logit_r, load, unload, nu = np.asarray(theta, dtype=float)
        k0, w0 = np.exp(log_k0), np.exp(log_w0)
        r = 1.0 / (1.0 + np.exp(-logit_r))
        m = k0 / w0**2
        return cls(m=m, c=2.0 * np.exp(log_zeta) * k0 / w0, k=k0 * (1.0 - r), alpha=k0 * r,
                   beta=0.5 * (load + unload), gamma=0.5 * (load - unload), nu=nu)


# The benchmark's system (Noel & Schoukens 2016, BoucWenBenchmark.pdf): m_L = 2 kg,
# c_L = 10 N s/m, k_L = 5e4 N/m, alpha = 5e4 N/m, beta = 1e3 m^-1, gamma = 0.8, delta = -1.1,
# nu = 1. They reproduce the noiseless validation data to 1e-7 m (docs/models/boucwen.md).
BENCHMARK_PARAMS = BoucWenParams.from_benchmark(m=2.0, c=10.0, k=5e4, alpha=5e4, beta=1e3,
                                                gamma=0.8, delta=-1.1, nu=1.0)
