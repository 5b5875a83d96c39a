"""The virtual sensor's causal physics as a loop model: the "real" sensor S_r of ch. 7.

The document had no FEM model of its sensor (ch. 6) and ran its loop with a fitted model as the
real sensor. :class:`~hystkit.sensors.VirtualSensor` is a physically motivated stand-in, but its
recordings go through a zero-phase filter and are referred to the recording mean, neither of
which a sensor in a loop can do. This module keeps what is causal -- steps 1-4 of its
docstring, through the same compiled per-sample laws (:mod:`._physics`) -- and runs it sample
by sample at any sample time, behind the running half of the family protocol
(:mod:`hystkit.models._protocol`). It is not a registered family: there is nothing to fit.

Input: tip deflection [mm]. Output: ``dR1/R1 - dR2/R2`` relative to the gauges at rest on the
unstrained beam (``x = 0``, before any cycling) -- the units of the simulator's recordings, so a
compensator fitted on :func:`~hystkit.sensors.simulate_experiment` applies, with the reference
a causal rest state instead of a recording mean (the loop starts at rest at 0, and
:func:`hystkit.control.tare` zeroes the remaining offset).

Left out, deliberately:

- measurement noise, the encoder and the 20 Hz zero-phase filter (step 5): the block is
  deterministic; the closed loop has its own sensor-noise input;
- the temperature excursion (a random process; its mean is 0) and post-print settling (for the
  default 48 h old print a drift below 4e-8 per second, under 2e-7 over the 5 s loop, against
  a signal spanning 0.33 on the 3 mm sine): both need time in the state, which would leave no
  state at rest;
- base resistances: they cancel in ``dR/R``.

State (float64), per gauge g = 1 (top, strain ``+kappa x``), 2 (bottom, ``-kappa x``)::

    q_g (Prony, P)   p_g (plays, J)   ... then   s_prev (last strain)   travel
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..models import Block, Record
from ._physics import (
    instant_fraction,
    network_step,
    piezoresistance,
    prony_decay,
    softening_factor,
    travel_step,
)
from ._virtual import VirtualSensor

__all__ = ["VIRTUAL_PHYSICS", "VirtualPhysics", "VirtualPhysicsParams",
           "VirtualPhysicsStructure", "physics_of"]

SIGNS = (1.0, -1.0)  # strain sign of the top and the bottom gauge


@dataclass(frozen=True)
class VirtualPhysicsStructure(Record):
    """What sets the state and the sample time.

    ``decay`` (``exp(-dt / tau)`` per Prony term) is derived from `dt`.

    Parameters
    ----------
    dt : float
        Sample time [s].
    prony_taus : tuple of float
        Prony time constants [s].
    play_radii : tuple of float
        Play radii [strain].
    """

    dt: float
    prony_taus: tuple[float, ...]
    play_radii: tuple[float, ...]
    decay: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.dt) and self.dt > 0):
            raise ValueError(f"dt must be positive, got {self.dt!r}")
        if min(self.prony_taus, default=1.0) <= 0 or min(self.play_radii, default=1.0) <= 0:
            raise ValueError("Prony time constants and play radii must be positive")
        object.__setattr__(self, "prony_taus", tuple(map(float, self.prony_taus)))
        object.__setattr__(self, "play_radii", tuple(map(float, self.play_radii)))
        object.__setattr__(self, "decay", tuple(prony_decay(self.prony_taus, self.dt)))

    @property
    def n_state(self) -> int:
        return 2 * (len(self.prony_taus) + len(self.play_radii)) + 2


@dataclass(frozen=True)
class VirtualPhysicsParams(Record):
    """The material and gauge quantities of :class:`~hystkit.sensors.VirtualSensor` that reach
    ``dR/R`` (same names and units).

    Parameters
    ----------
    strain_per_mm : float
        Surface strain per mm of tip deflection [1/mm].
    prony_fractions : tuple of float
        Share of the imposed strain each Prony term retards [-].
    play_weights : tuple of float
        Weights of the play operators [-].
    gauge_factors : (float, float)
        gamma of R1 and R2 [-].
    softening : (float, float)
        Saturated relative resistance rise of R1 and R2 [-].
    softening_travel : float
        Accumulated strain travel per e-fold of the softening [strain].
    """

    strain_per_mm: float
    prony_fractions: tuple[float, ...]
    play_weights: tuple[float, ...]
    gauge_factors: tuple[float, float]
    softening: tuple[float, float]
    softening_travel: float

    def __post_init__(self) -> None:
        for name in ("prony_fractions", "play_weights", "gauge_factors", "softening"):
            object.__setattr__(self, name, tuple(map(float, getattr(self, name))))
        if len(self.gauge_factors) != 2 or len(self.softening) != 2:
            raise ValueError("gauge_factors and softening hold one value per gauge (two)")
        if not self.softening_travel > 0:
            raise ValueError("softening_travel must be positive")


def physics_of(sensor: VirtualSensor | None = None, dt: float | None = None,
               ) -> tuple[VirtualPhysicsStructure, VirtualPhysicsParams]:
    """Structure and parameters of ``sensor``'s causal physics at sample time ``dt``.

    Defaults: ``VirtualSensor()`` and its simulation step ``1 / fs_internal``.

    Parameters
    ----------
    sensor : VirtualSensor, optional
        The simulated sensor.
    dt : float, optional
        Sample time [s].

    Returns
    -------
    structure : VirtualPhysicsStructure
        `dt`, Prony time constants and play radii.
    params : VirtualPhysicsParams
        The sensor's quantities that reach dR/R.
    """
    sensor = VirtualSensor() if sensor is None else sensor
    dt = 1.0 / sensor.fs_internal if dt is None else float(dt)
    return (VirtualPhysicsStructure(dt, sensor.prony_taus, sensor.play_radii),
            VirtualPhysicsParams(sensor.strain_per_mm, sensor.prony_fractions,
                                 sensor.play_weights, sensor.gauge_factors, sensor.softening,
                                 sensor.softening_travel))


def _body(structure: VirtualPhysicsStructure, params: VirtualPhysicsParams) -> np.ndarray:
    """Flat parameters: ``[P, J, c, kappa, travel scale, gamma_1, gamma_2, a_1, a_2,
    fractions (P), decay (P), weights (J), radii (J)]``."""
    if (len(params.prony_fractions) != len(structure.prony_taus)
            or len(params.play_weights) != len(structure.play_radii)):
        raise ValueError("parameters and structure differ in the number of Prony terms or "
                         "play operators")
    head = [len(structure.prony_taus), len(structure.play_radii),
            instant_fraction(params.prony_fractions, params.play_weights),
            params.strain_per_mm, params.softening_travel, *params.gauge_factors,
            *params.softening]
    return np.ascontiguousarray(np.concatenate([head, params.prony_fractions, structure.decay,
                                                params.play_weights, structure.play_radii]),
                                dtype=np.float64)


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """One sample: ``u`` [mm] -> ``dR1/R1 - dR2/R2`` from ``x[off:]``, next state to ``xn``."""
    p, j = int(body[0]), int(body[1])
    n = p + j
    fractions, decay = body[9:9 + p], body[9 + p:9 + 2 * p]
    weights, radii = body[9 + 2 * p:9 + 2 * p + j], body[9 + 2 * p + j:9 + 2 * n]
    s = body[3] * u  # step 1: surface strain of the top gauge
    travel = travel_step(x[off + 2 * n + 1], s, x[off + 2 * n])
    xn[off + 2 * n] = s
    xn[off + 2 * n + 1] = travel
    out = 0.0
    for g in range(2):
        sign = 1.0 - 2.0 * g
        a = off + g * n
        m = network_step(sign * s, body[2], fractions, decay, weights, radii, x[a:a + p],
                         x[a + p:a + n], xn[a:a + p], xn[a + p:a + n])
        ratio = softening_factor(travel, body[7 + g], body[4]) * piezoresistance(m, body[5 + g])
        out += sign * (ratio - 1.0)
    return out


@njit(cache=True)
def _simulate(body, u, x0):
    x, xn = x0.copy(), x0.copy()
    y = np.empty(u.size)
    for k in range(u.size):
        y[k] = block_forward(body, x, xn, 0, u[k])
        x, xn = xn, x
    return y, x


class VirtualPhysics:
    """The running methods of the family protocol for the virtual sensor's physics.

    Forward only (position [mm] -> ``dR1/R1 - dR2/R2``); no ``fit``, no inverse. Pass it as
    ``SensorBlock(..., model_family=VIRTUAL_PHYSICS)``
    (:func:`hystkit.control.virtual_sensor_block`).
    """

    name = "virtual-physics"
    title = "virtual sensor physics, causal (hystkit.sensors.VirtualSensor steps 1-4)"
    Structure = VirtualPhysicsStructure
    Params = VirtualPhysicsParams
    invert = None
    invert_step = None
    has_inverse = False
    no_inverse_reason = "the virtual sensor is simulated forward only"

    def __repr__(self) -> str:
        return "<virtual sensor physics (loop model, not a fittable family)>"

    @staticmethod
    def _forward_only(inverse: bool) -> None:
        if inverse:
            raise ValueError(f"virtual-physics has no inverse ({VirtualPhysics.no_inverse_reason})")

    def at(self, structure: VirtualPhysicsStructure, dt: float) -> VirtualPhysicsStructure:
        """The same physics at sample time ``dt``: the Prony decays are recomputed (exact for a
        held input), the plays and softening are rate independent."""
        return dataclasses.replace(structure, dt=float(dt))

    def rest_state(self, structure, params, value, inverse=False) -> np.ndarray:
        """At rest at deflection ``value`` [mm]: Prony states at the strain, plays brought there
        from their virgin state (as the simulator starts), no travel yet."""
        self._forward_only(inverse)
        p, j = len(structure.prony_taus), len(structure.play_radii)
        body = _body(structure, params)
        s = params.strain_per_mm * float(value)
        x = np.empty(structure.n_state)
        for g, sign in enumerate(SIGNS):
            a = g * (p + j)
            x[a:a + p] = sign * s
            x[a + p:a + p + j] = 0.0  # virgin, then moved to the strain by one step below
            network_step(sign * s, body[2], body[9:9 + p], body[9 + p:9 + 2 * p],
                         body[9 + 2 * p:9 + 2 * p + j], body[9 + 2 * p + j:],
                         x[a:a + p], x[a + p:a + p + j], x[a:a + p], x[a + p:a + p + j])
        x[-2:] = s, 0.0
        return x

    def step(self, structure, params, x, u) -> tuple[float, np.ndarray]:
        """Readable reference: steps 1-4 one after the other on a copy of the state."""
        p, j = len(structure.prony_taus), len(structure.play_radii)
        n = p + j
        x = np.array(x, dtype=float)
        xn = x.copy()
        c = instant_fraction(params.prony_fractions, params.play_weights)
        fractions, weights = np.array(params.prony_fractions), np.array(params.play_weights)
        decay, radii = np.array(structure.decay), np.array(structure.play_radii)
        s = params.strain_per_mm * float(u)                          # 1. beam
        travel = travel_step(x[2 * n + 1], s, x[2 * n])
        xn[2 * n:] = s, travel
        ratio = []
        for g, sign in enumerate(SIGNS):
            a = g * n
            m = network_step(sign * s, c, fractions, decay, weights, radii,     # 2. network
                             x[a:a + p], x[a + p:a + n], xn[a:a + p], xn[a + p:a + n])
            ratio.append(softening_factor(travel, params.softening[g], params.softening_travel)
                         * piezoresistance(m, params.gauge_factors[g]))        # 4. and 3.
        return float((ratio[0] - 1.0) - (ratio[1] - 1.0)), xn

    def simulate(self, structure, params, u, x0=None) -> tuple[np.ndarray, np.ndarray]:
        """Run over ``u`` [mm] (compiled); ``x0=None`` starts at rest at ``u[0]``."""
        u = np.ascontiguousarray(u, dtype=np.float64)
        body = _body(structure, params)
        x0 = self.rest_state(structure, params, float(u[0]) if u.size else 0.0) if x0 is None \
            else np.array(x0, dtype=np.float64)
        if x0.size != structure.n_state:
            raise ValueError(f"state of length {x0.size}; this structure has "
                             f"{structure.n_state}")
        return _simulate(body, u, x0)

    def block(self, structure, params, inverse=False) -> Block:
        self._forward_only(inverse)
        return Block(block_forward, _body(structure, params), structure.n_state)

    def linearise(self, structure, params, x, u, inverse=False):
        """Jacobian of one step, analytical; neutral memory not reported as poles at ``z = 1``.

        Prony states: ``decay`` and ``1 - decay``. A play on the edge of its band (or pushed
        beyond) moves with the input (``dp+/dp = 0``, ``dp+/ds = 1``); strictly inside it is
        frozen memory that the input cannot reach. The travel integrates ``|ds|``: slope
        ``sign(s - s_prev)``, 0 at rest (the mean of the kink's two slopes). A frozen play and
        the travel at rest get a zero row instead of the identity row (``B = 0`` there, so the
        input-output behaviour is the same; as the Preisach family does), so that the loop's
        eigenvalue test does not count memory as marginal poles.
        """
        self._forward_only(inverse)
        p, j = len(structure.prony_taus), len(structure.play_radii)
        n = p + j
        x = np.asarray(x, dtype=float)
        kappa = params.strain_per_mm
        s = kappa * float(u)
        xn = self.step(structure, params, x, u)[1]
        decay, radii = np.array(structure.decay), np.array(structure.play_radii)
        fractions, weights = np.array(params.prony_fractions), np.array(params.play_weights)
        c = instant_fraction(params.prony_fractions, params.play_weights)
        direction = float(np.sign(s - x[2 * n]))
        travel = xn[2 * n + 1]
        a = np.zeros((2 * n + 2, 2 * n + 2))
        b = np.zeros(2 * n + 2)
        cc = np.zeros(2 * n + 2)
        d = 0.0
        for g, sign in enumerate(SIGNS):
            o = g * n
            # on the edge up to rounding (a rest state beyond the radius) counts as moving
            moving = (np.abs(sign * s - x[o + p:o + n]) >= radii * (1 - 1e-12)).astype(float)
            a[o:o + p, o:o + p] = np.diag(decay)
            b[o:o + p] = sign * kappa * (1.0 - decay)
            # play rows of A stay 0: a moving play forgets, a frozen one is neutral (see above)
            b[o + p:o + n] = sign * kappa * moving
            m = (c * sign * s + fractions @ x[o:o + p] + weights @ xn[o + p:o + n])
            law = piezoresistance(m, params.gauge_factors[g])
            soft = softening_factor(travel, params.softening[g], params.softening_travel)
            # d ratio / d m and d ratio / d travel (softening' = (a - (F - 1)) / scale)
            dr_dm = soft * law * params.gauge_factors[g]
            dr_dt = law * (params.softening[g] - (soft - 1.0)) / params.softening_travel
            cc[o:o + p] += sign * dr_dm * fractions
            cc[o + p:o + n] += sign * dr_dm * weights * (1.0 - moving)
            d += sign * dr_dm * sign * kappa * (c + weights @ moving)
            cc[2 * n] += sign * dr_dt * -direction
            cc[2 * n + 1] += sign * dr_dt
            d += sign * dr_dt * direction * kappa
        b[2 * n] = kappa  # s_prev+ = s
        a[2 * n + 1, 2 * n] = -direction
        a[2 * n + 1, 2 * n + 1] = 1.0 if direction else 0.0  # at rest: neutral, see above
        b[2 * n + 1] = direction * kappa
        return a, b, cc, float(d)


VIRTUAL_PHYSICS = VirtualPhysics()
"""The one instance to pass as ``model_family``."""
