"""Compiled hot loops of the Bouc-Wen oscillator; ``model.py`` holds the reference and checks.

All arrays are float64 and already validated by the caller. ``theta`` is the physical parameter
vector ``(m, c, k, alpha, beta, gamma, nu)``; the state is ``(y, v, z, u_prev)`` with ``v = dy/dt``
(see ``model.py`` for the sampling convention).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _rhs(y, v, z, u, inv_m, c, k, alpha, beta, gamma, nu):
    """Right-hand side ``(dy/dt, dv/dt, dz/dt)`` of the oscillator with Bouc-Wen force ``z``
    (``inv_m = 1 / m``)."""
    # |z|^nu; numba's float ** defeats the optimiser here (4x slower even when not taken), and
    # exp(nu log|z|) is exact enough and gives 0 at z = 0 for nu >= 1.
    p = abs(z) if nu == 1.0 else np.exp(nu * np.log(abs(z)))
    q = p if z >= 0.0 else -p  # |z|^(nu - 1) z, written so that z = 0 needs no 0^(nu - 1)
    dz = alpha * v - beta * abs(v) * q - gamma * v * p
    return v, (u - c * v - k * y - z) * inv_m, dz


@njit(cache=True, inline="always")
def advance(x, u_a, u_b, theta, h, n_sub, linear):
    """Integrate ``x = (y, v, z)`` over one sample of ``n_sub`` RK4 substeps of length ``h``.

    The force moves linearly from ``u_a`` to ``u_b`` over the sample (``linear``) or is held at
    ``u_a`` (zero-order hold). ``x`` is updated in place.
    """
    m, c, k, alpha, beta, gamma, nu = theta
    # times 1 / m, not / m: eight divisions per sample on the serial RK4 chain were a third of
    # its time (66.8 -> 48.6 ns/sample, 2 substeps); the outputs move by ~1e-14 relative
    inv_m = 1.0 / m
    y, v, z = x[0], x[1], x[2]
    du = (u_b - u_a) / n_sub if linear else 0.0
    for j in range(n_sub):
        u0 = u_a + j * du
        u1 = u0 + 0.5 * du
        u2 = u0 + du
        k1y, k1v, k1z = _rhs(y, v, z, u0, inv_m, c, k, alpha, beta, gamma, nu)
        k2y, k2v, k2z = _rhs(y + 0.5 * h * k1y, v + 0.5 * h * k1v, z + 0.5 * h * k1z, u1,
                             inv_m, c, k, alpha, beta, gamma, nu)
        k3y, k3v, k3z = _rhs(y + 0.5 * h * k2y, v + 0.5 * h * k2v, z + 0.5 * h * k2z, u1,
                             inv_m, c, k, alpha, beta, gamma, nu)
        k4y, k4v, k4z = _rhs(y + h * k3y, v + h * k3v, z + h * k3z, u2,
                             inv_m, c, k, alpha, beta, gamma, nu)
        y += h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y)
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
        z += h / 6.0 * (k1z + 2.0 * k2z + 2.0 * k3z + k4z)
    x[0], x[1], x[2] = y, v, z


@njit(cache=True)
def simulate(u, x0, fresh, theta, dt, n_sub, linear, bound):
    """States ``(y, v, z)`` at every sample, the final state and the first diverged sample.

    ``fresh``: ``x0`` holds the state at the first sample itself (nothing to integrate before
    it, ``x0[3] = u[0]``); otherwise ``x0 = (y, v, z, u_prev)`` is the state one sample
    earlier. A sample whose state is not finite, or whose ``|y|`` exceeds ``bound``, stops the
    run; its index is returned (-1 if none).
    """
    n = u.size
    states = np.empty((n, 3))
    x = x0[:3].copy()
    u_prev = x0[3]
    h = dt / n_sub
    for i in range(n):
        if i > 0 or not fresh:
            advance(x, u_prev, u[i], theta, h, n_sub, linear)
            if not (abs(x[0]) <= bound and np.isfinite(x[1]) and np.isfinite(x[2])):
                return states, np.array([x[0], x[1], x[2], u[i]]), i
        states[i, 0], states[i, 1], states[i, 2] = x[0], x[1], x[2]
        u_prev = u[i]
    return states, np.array([x[0], x[1], x[2], u_prev]), -1


# Loop blocks (protocol in ``hystkit.models._protocol``): body = [m, c, k, alpha, beta, gamma,
# nu, dt, substeps, linear (1 or 0)]; the state slice is ``(y, v, z, u_prev)`` as in ``step``.

@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """Integrate from the previous force sample to ``u`` (held or linear, as ``advance``)."""
    n_sub = int(body[8])
    s = xn[off:off + 3]
    s[0], s[1], s[2] = x[off], x[off + 1], x[off + 2]
    advance(s, x[off + 3], u, body[:7], body[7] / n_sub, n_sub, body[9] != 0.0)
    xn[off + 3] = u
    return s[0]
