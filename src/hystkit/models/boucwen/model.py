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

import numpy as np

from ...errors import FitDivergedError
from .._docs import RECORDS, docfiller
from .._validation import check_signal
from . import kernels
from .divergence import (
    bounded_class,
    divergence_bound,
    divergence_message,
)
from .records import (
    BENCHMARK_PARAMS,
    HOLDS,
    MAX_NU,
    MAX_SUBSTEPS,
    STARTS,
    BoucWenParams,
    BoucWenStructure,
)

# the arguments of the three runs (simulate_states, simulate, simulate_reference)
_RUN_ARGUMENTS = """Parameters
----------
""" + RECORDS + """
u : numpy.ndarray, shape (n,)
    Force sampled every ``structure.dt``.
x0 : numpy.ndarray, shape (4,), optional
    State ``(y, y', z, u_prev)`` one sample before ``u[0]`` (the ``x_end`` of a previous
    run); None starts at ``u[0]`` as ``structure.start`` says (:func:`initial_state`)."""

fill_doc = docfiller("BoucWenStructure", "BoucWenParams", entries={"run": _RUN_ARGUMENTS})

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

def _rhs(params: BoucWenParams, y: float, v: float, z: float, u: float):
    p = abs(z) ** params.nu
    q = p if z >= 0 else -p  # |z|^(nu - 1) z
    dz = params.alpha * v - params.beta * abs(v) * q - params.gamma * v * p
    return np.array([v, (u - params.c * v - params.k * y - z) / params.m, dz])


@fill_doc
def step(structure: BoucWenStructure, params: BoucWenParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample of the model (readable reference): integrate to the next force sample.

    Parameters
    ----------
    %(structure)s
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


@fill_doc
def initial_state(structure: BoucWenStructure, params: BoucWenParams,
                  u0: float) -> np.ndarray:
    """``(y, y', z, u0)`` at the first sample of a run without ``x0`` (``structure.start``).

    Parameters
    ----------
    %(structure)s
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


@fill_doc
def rest_state(structure: BoucWenStructure, params: BoucWenParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """The start of :func:`simulate` with ``x0=None`` (:func:`initial_state`) for the force
    ``value``. With ``start="equilibrium"`` (the family's) it is an equilibrium, a fixed point
    of :func:`step`; ``start="rest"`` (``y = z = 0``) is one only for ``value = 0``.

    Parameters
    ----------
    %(structure)s
    value : float
        Constant force.
    inverse : bool, default False
        Must be False: the model has no inverse.

    Returns
    -------
    %(rest_returns)s

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


@fill_doc
def simulate_states(structure: BoucWenStructure, params: BoucWenParams, u: np.ndarray,
                    x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the model and return every sample's mechanical state (compiled kernel).

    %(run)s

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


@fill_doc
def simulate(structure: BoucWenStructure, params: BoucWenParams, u: np.ndarray,
             x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Displacement response to a force sequence (see :func:`simulate_states`).

    %(run)s

    Returns
    -------
    y : array, shape (n,)
    x_end : array, shape (4,)
        Feeding it back as ``x0`` continues the run exactly.
    """
    states, x_end = simulate_states(structure, params, u, x0)
    return states[:, 0].copy(), x_end


@fill_doc
def simulate_reference(structure: BoucWenStructure, params: BoucWenParams, u: np.ndarray,
                       x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Same as :func:`simulate`, as a plain loop over :func:`step` (the readable reference).

    %(run)s

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
