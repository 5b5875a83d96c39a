"""Bouc-Wen hysteresis with a linear dynamic part (single-degree-of-freedom oscillator).

Not in the reference document; added so that the public Bouc-Wen benchmark of Noel and
Schoukens (2016) can be run. A mass ``m`` on a damper ``c`` and a spring ``k`` in parallel with a
hysteretic element of force ``z`` is driven by a force ``u``; the output is the displacement
``y``::

    m y'' + c y' + k y + z = u
    z' = alpha y' - beta |y'| |z|^(nu - 1) z - gamma y' |z|^nu

the classical form of Wen (1976; see Ismail, Ikhouane and Rodellar, Arch. Comput. Methods Eng.
16, 2009, whose ``A`` and ``n`` are ``alpha`` and ``nu`` here). The benchmark writes
``z' = alpha y' - beta_b (gamma_b |y'| |z|^(nu-1) z + delta_b y' |z|^nu)``, in which only the
products ``beta_b gamma_b`` and ``beta_b delta_b`` can be identified; here they are ``beta`` and
``gamma`` (:meth:`BoucWenParams.from_benchmark`). The state is ``(y, y', z)``; on the benchmark
``u`` is in N and ``y`` in m, on the virtual sensor both are normalised (eq. 5.10) and the
parameters are dimensionless.

Sampling convention. ``u[n]`` and ``y[n]`` are the force and displacement at ``t_n = n dt``.
Between samples the force is interpolated linearly (``input_hold="linear"``, first-order hold)
or held (``"zoh"``), and the ODE is integrated with the classical fourth-order Runge-Kutta
method in ``substeps`` equal steps per sample. RK4 has order 4 while the right-hand side is
smooth (``beta = gamma = 0``: a linear oscillator). ``|y'|`` and ``|z|`` make it only Lipschitz
where ``y'`` or ``z`` change sign: the step across such a point integrates a kinked integrand and
makes a local error O(h^2), and as a run crosses them a fixed number of times per unit time, the
global order of hysteretic runs is 2 (tests/models/boucwen/test_boucwen.py measures both).
Locating the crossings would restore order 4; at the benchmark's step sizes the error is already
far below the published model errors (docs/models/boucwen.md).

Memory is the explicit state ``x = (y, y', z, u_prev)``: the mechanical state at the last
sample processed and the force there, which the next interval interpolates from. ``x0=None``
starts at the first sample with ``y' = 0`` and either at rest (``start="rest"``: ``y = z = 0``,
as the benchmark data were generated, even though ``u[0] != 0`` then jerks the mass) or in the
small-signal equilibrium with the first force (``start="equilibrium"``: ``z = alpha y`` and
``k y + z = u[0]``, the synchronised start of eq. 2.21-2.22 that the virtual-sensor family
uses). Passing the returned ``x_end`` as ``x0`` continues a run exactly.

The benchmark's generator integrated with Newmark at 15 kHz a force defined at 15 kHz, then
decimated to 750 Hz. A force known only at 750 Hz is band-limited (multisine up to 150 Hz), so
the model is run on it after band-limited interpolation (:func:`bandlimited_upsample`); linear
interpolation at 750 Hz alone loses 12 % of the amplitude at 150 Hz (sinc^2 droop).
:func:`step`, :func:`simulate` and the closed loop's compiled block all use the causal
per-sample scheme above (they agree to round-off); band-limiting needs the whole record, so it
stays a preprocessing step, and a loop running on raw samples sees the droop ``sinc^2(f dt)``
(1.3e-3 at 2 % of the sample rate, 3 % at 10 %).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import FitDivergedError
from .._protocol import Record
from .._validation import check_dt, check_signal
from . import kernels

__all__ = [
    "BENCHMARK_PARAMS",
    "HOLDS",
    "MAX_NU",
    "MAX_SUBSTEPS",
    "STARTS",
    "BoucWenParams",
    "BoucWenStructure",
    "bandlimited_upsample",
    "bounded_class",
    "divergence_bound",
    "divergence_message",
    "initial_state",
    "rest_state",
    "simulate",
    "simulate_reference",
    "simulate_states",
    "step",
]

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


def _rhs(params: BoucWenParams, y: float, v: float, z: float, u: float):
    p = abs(z) ** params.nu
    q = p if z >= 0 else -p  # |z|^(nu - 1) z
    dz = params.alpha * v - params.beta * abs(v) * q - params.gamma * v * p
    return np.array([v, (u - params.c * v - params.k * y - z) / params.m, dz])


def step(structure: BoucWenStructure, params: BoucWenParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample of the model (readable reference): integrate to the next force sample.

    Parameters
    ----------
    structure : BoucWenStructure
        The model's structure.
    params : BoucWenParams
        Its parameters.
    x : array, shape (4,)
        ``(y, y', z, u_prev)`` at the previous sample.
    u : float
        Force at the new sample.

    Returns
    -------
    y : float
        Displacement at the new sample.
    x_next : array, shape (4,)
    """
    s = np.asarray(x[:3], dtype=float)
    h = structure.step_size
    n_sub = structure.substeps
    u_a = float(x[3])
    du = (u - u_a) / n_sub if structure.input_hold == "linear" else 0.0
    for j in range(n_sub):
        u0 = u_a + j * du
        k1 = _rhs(params, *s, u0)
        k2 = _rhs(params, *(s + 0.5 * h * k1), u0 + 0.5 * du)
        k3 = _rhs(params, *(s + 0.5 * h * k2), u0 + 0.5 * du)
        k4 = _rhs(params, *(s + h * k3), u0 + du)
        s = s + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return float(s[0]), np.append(s, u)


def initial_state(structure: BoucWenStructure, params: BoucWenParams,
                  u0: float) -> np.ndarray:
    """``(y, y', z, u0)`` at the first sample of a run without ``x0`` (``structure.start``).

    Parameters
    ----------
    structure : BoucWenStructure
        The model's structure.
    params : BoucWenParams
        Its parameters.
    u0 : float
        Force at the first sample.

    Returns
    -------
    numpy.ndarray, shape (4,)
        ``(0, 0, 0, u0)`` for ``start="rest"``; the static equilibrium
        ``(u0 / K0, 0, alpha u0 / K0, u0)`` for ``start="equilibrium"``.
    """
    if structure.start == "rest":
        return np.array([0.0, 0.0, 0.0, u0])
    with np.errstate(over="ignore"):  # a tiny K0 overflows; simulate_states reports it
        y0 = np.float64(u0) / params.k0
    return np.array([y0, 0.0, params.alpha * y0, u0])


def rest_state(structure: BoucWenStructure, params: BoucWenParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """The start of :func:`simulate` with ``x0=None`` (:func:`initial_state`) for the force
    ``value``. With ``start="equilibrium"`` (the family's) it is an equilibrium, a fixed point
    of :func:`step`; ``start="rest"`` (``y = z = 0``) is one only for ``value = 0``.

    Parameters
    ----------
    structure : BoucWenStructure
        The model's structure.
    params : BoucWenParams
        Its parameters.
    value : float
        Constant force.
    inverse : bool, default False
        Must be False: the model has no inverse.

    Returns
    -------
    numpy.ndarray
        The state at rest.

    Raises
    ------
    ValueError
        For ``inverse``: the model has no inverse.
    """
    if inverse:
        raise ValueError("the Bouc-Wen model has no inverse (force in, displacement out of a "
                         "second-order system)")
    return initial_state(structure, params, float(value))


def _initial_state(structure: BoucWenStructure, params: BoucWenParams, x0: np.ndarray | None,
                   u0: float) -> tuple[np.ndarray, bool]:
    """``(state, fresh)``: ``fresh`` when ``state`` is already at the first sample."""
    if x0 is None:
        return initial_state(structure, params, u0), True
    x0 = np.asarray(x0, dtype=float)
    if x0.shape != (4,) or not np.all(np.isfinite(x0)):
        raise ValueError(f"x0 must be None or 4 finite values (y, y', z, u_prev), got {x0!r}")
    return x0.copy(), False


def simulate_states(structure: BoucWenStructure, params: BoucWenParams, u: np.ndarray,
                    x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the model and return every sample's mechanical state (compiled kernel).

    Parameters
    ----------
    structure : BoucWenStructure
        The model's structure.
    params : BoucWenParams
        Its parameters.
    u : array, shape (n,)
        Force sampled every ``structure.dt``.
    x0 : array, shape (4,), or None
        State ``(y, y', z, u_prev)`` one sample before ``u[0]`` (the ``x_end`` of a previous
        run); ``None`` starts at ``u[0]`` as ``structure.start`` says (:func:`initial_state`).

    Returns
    -------
    states : array, shape (n, 3)
        ``(y, y', z)`` at every sample.
    x_end : array, shape (4,)

    Raises
    ------
    FitDivergedError
        If the integration diverges (:func:`divergence_bound`): the message names the sample
        and the likely cause (RK4 step too long, or a loop outside the bounded class).
    """
    u = check_signal(u, "u")
    x, fresh = _initial_state(structure, params, x0, u[0])
    if not np.all(np.isfinite(x)):
        raise FitDivergedError(f"the Bouc-Wen state diverged at sample 1 of {u.size}: the "
                               f"start (y, y', z) = {tuple(x[:3].tolist())} overflows "
                               f"(u[0] / K0 with K0 = {params.k0:.3g})")
    bound = divergence_bound(structure, params, x, u)
    states, x_end, n_bad = kernels.simulate(u, x, fresh, params.as_array(), structure.dt,
                                            structure.substeps,
                                            structure.input_hold == "linear", bound)
    if n_bad >= 0:
        raise FitDivergedError(divergence_message(structure, params, x_end, n_bad, u.size,
                                                   bound))
    return states, x_end


def bounded_class(params: BoucWenParams) -> bool:
    """``beta + gamma >= 0`` and ``beta - gamma >= 0``: ``z`` stays bounded, loops dissipate.

    Parameters
    ----------
    params : BoucWenParams
        The model's parameters.

    Returns
    -------
    bool
        True when both sums are non-negative.
    """
    return params.beta + params.gamma >= 0 and params.beta - params.gamma >= 0


def divergence_bound(structure: BoucWenStructure, params: BoucWenParams, x: np.ndarray,
                     u: np.ndarray) -> float:
    """A bound on ``|y|`` that the exact solution cannot exceed over a run of ``u`` from ``x``.

    In the bounded class the element is passive: with ``E = m v^2 / 2 + k y^2 / 2 +
    z^2 / (2 alpha)``, ``dE/dt = u v - c v^2 - |v| |z|^(nu+1) (beta + gamma sign(v z)) / alpha
    <= u^2 / (4 c)``, so ``|y| <= sqrt(2 (E_0 + T max u^2 / (4 c)) / k)`` over the run's
    duration ``T``. Twice that (room for the integration error) is returned; an RK4 run beyond
    it has diverged numerically. Outside the class ``z`` may grow without limit and the bound
    is ``inf`` (only a non-finite state stops the run).

    Parameters
    ----------
    structure : BoucWenStructure
        The model's structure.
    params : BoucWenParams
        Its parameters.
    x : numpy.ndarray, shape (4,)
        State ``(y, y', z, u_prev)`` at the start of the run.
    u : numpy.ndarray, shape (n,)
        The run's force.

    Returns
    -------
    float
        The bound on ``|y|``, ``inf`` outside the bounded class.
    """
    if not bounded_class(params):
        return np.inf
    y0, v0, z0, u_prev = np.asarray(x, dtype=np.float64)  # numpy floats overflow to inf
    with np.errstate(over="ignore", invalid="ignore"):
        energy = 0.5 * params.m * v0**2 + 0.5 * params.k * y0**2 + z0**2 / (2 * params.alpha)
        u_max = max(float(np.max(np.abs(u))), abs(u_prev))
        energy += u.size * structure.dt * u_max**2 / (4 * params.c)
        return float(2.0 * np.sqrt(2.0 * energy / params.k))


def divergence_message(structure: BoucWenStructure, params: BoucWenParams, x: np.ndarray,
                        n_bad: int, n: int, bound: float) -> str:
    """What happened (the state at the sample it diverged) and the likely cause.

    Parameters
    ----------
    structure : BoucWenStructure
        The model's structure.
    params : BoucWenParams
        Its parameters.
    x : numpy.ndarray
        State at the sample where the run diverged.
    n_bad : int
        That sample (0-based).
    n : int
        Samples in the run.
    bound : float
        The bound of :func:`divergence_bound` (``inf`` for none).

    Returns
    -------
    str
        One line for the error message.
    """
    w0h = params.omega0 * structure.step_size
    state = f"(y, y', z) = ({x[0]:.3g}, {x[1]:.3g}, {x[2]:.3g})"
    what = (f"the Bouc-Wen state diverged at sample {n_bad + 1} of {n}: {state}"
            + ("" if np.isinf(bound) else f", beyond the bound |y| <= {bound:.3g}"))
    if w0h > RK4_LIMIT:
        cause = (f"the RK4 step {structure.step_size:.3g} s is too long for w0 = "
                 f"{params.omega0:.3g} rad/s (w0 h = {w0h:.3g} > {RK4_LIMIT}); use more "
                 f"substeps")
    elif not bounded_class(params):
        cause = (f"beta + gamma = {params.beta + params.gamma:.3g} and beta - gamma = "
                 f"{params.beta - params.gamma:.3g} are not both >= 0, so the hysteretic force "
                 f"z is not bounded")
    else:
        cause = (f"w0 h = {w0h:.3g} is within RK4's limit, so the hysteretic element (beta, "
                 f"gamma, nu = {params.beta:.3g}, {params.gamma:.3g}, {params.nu:.3g}) is too "
                 f"stiff for the RK4 step {structure.step_size:.3g} s; use more substeps")
    return f"{what}; {cause}"


def simulate(structure: BoucWenStructure, params: BoucWenParams, u: np.ndarray,
             x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Displacement response to a force sequence (see :func:`simulate_states`).

    Parameters
    ----------
    structure : BoucWenStructure
        The model's structure.
    params : BoucWenParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Force sampled every ``structure.dt``.
    x0 : numpy.ndarray, shape (4,), optional
        State ``(y, y', z, u_prev)`` one sample before ``u[0]``; None starts as
        ``structure.start`` says (:func:`initial_state`).

    Returns
    -------
    y : array, shape (n,)
    x_end : array, shape (4,)
        Feeding it back as ``x0`` continues the run exactly.
    """
    states, x_end = simulate_states(structure, params, u, x0)
    return states[:, 0].copy(), x_end


def simulate_reference(structure: BoucWenStructure, params: BoucWenParams, u: np.ndarray,
                       x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Same as :func:`simulate`, as a plain loop over :func:`step` (the readable reference).

    Parameters
    ----------
    structure : BoucWenStructure
        The model's structure.
    params : BoucWenParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Force sampled every ``structure.dt``.
    x0 : numpy.ndarray, shape (4,), optional
        State ``(y, y', z, u_prev)`` one sample before ``u[0]``; None starts as
        ``structure.start`` says (:func:`initial_state`).

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Output.
    x_end : numpy.ndarray
        State after the last sample.
    """
    u = check_signal(u, "u")
    x, fresh = _initial_state(structure, params, x0, u[0])
    y = np.empty_like(u)
    for n, u_n in enumerate(u):
        if n == 0 and fresh:
            y[0] = x[0]
        else:
            y[n], x = step(structure, params, x, u_n)
    return y, x


def bandlimited_upsample(u: np.ndarray, factor: int, periodic: bool) -> np.ndarray:
    """Band-limited interpolation of a force to ``factor`` times its sample rate.

    Parameters
    ----------
    u : array, shape (n,)
    factor : int
    periodic : bool
        ``True`` for one period of a periodic signal (a multisine): zero-padding of its DFT,
        exact for a signal without content at Nyquist. ``False``: polyphase FIR (Kaiser window,
        beta 10), accurate below about 0.8 Nyquist away from the ends.

    Returns
    -------
    array, shape (n * factor,)
        ``out[factor * i] == u[i]`` up to round-off (periodic) or the filter's accuracy.
    """
    u = check_signal(u, "u")
    if int(factor) != factor or factor < 1:
        raise ValueError(f"factor must be a positive integer, got {factor!r}")
    if factor == 1:
        return u.copy()
    if not periodic:
        # here: scipy.signal costs ~1 s to import, and only this input hold needs it
        from scipy.signal import resample_poly

        return resample_poly(u, factor, 1, window=("kaiser", 10.0))
    n = u.size
    spectrum = np.zeros(n * factor // 2 + 1, dtype=complex)
    half = np.fft.rfft(u)
    if n % 2 == 0:
        half[-1] *= 0.5  # the Nyquist bin splits between +fs/2 and -fs/2 of the finer grid
    spectrum[:half.size] = half
    return np.fft.irfft(spectrum, n * factor) * factor
