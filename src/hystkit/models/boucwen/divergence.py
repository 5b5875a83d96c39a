"""When a Bouc-Wen run has diverged, and why: the bounded class of the hysteretic element
(Ikhouane-Rodellar), the divergence threshold of a run and the message naming the likely cause
(an RK4 step too long for the linear part or for the hysteretic element).
"""

from __future__ import annotations

import numpy as np

from .._docs import docfiller
from .records import (
    RK4_LIMIT,
    BoucWenParams,
    BoucWenStructure,
)

fill_doc = docfiller("BoucWenStructure", "BoucWenParams")


@fill_doc
def bounded_class(params: BoucWenParams) -> bool:
    """``beta + gamma >= 0`` and ``beta - gamma >= 0``: ``z`` stays bounded, loops dissipate.

    Parameters
    ----------
    %(params)s

    Returns
    -------
    bool
        True when both sums are non-negative.
    """
    return params.beta + params.gamma >= 0 and params.beta - params.gamma >= 0


@fill_doc
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
    %(structure)s
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


@fill_doc
def divergence_message(structure: BoucWenStructure, params: BoucWenParams, x: np.ndarray,
                        n_bad: int, n: int, bound: float) -> str:
    """What happened (the state at the sample it diverged) and the likely cause.

    Parameters
    ----------
    %(structure)s
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
