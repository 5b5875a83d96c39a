"""The Kuhnen / modified Prandtl-Ishlinskii family (sec. 2.1.6, eq. 2.6-2.19) behind the family
protocol."""

from __future__ import annotations

import dataclasses

import numpy as np

from ...errors import FitDivergedError
from .._protocol import Block, Family
from . import INFO, box, kernels
from . import model as pi
from .export import TRANSLATION

__all__ = ["FAMILY", "PiFamily"]


class PiFamily(Family):
    """Kuhnen's modified Prandtl-Ishlinskii model with creep (sec. 2.1.6) as a registered family."""

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = pi.PiStructure
    Params = pi.PiParams
    model = pi  # rest_state, step, simulate, invert, invert_step: the module's functions

    fit_function = "fit.fit_pi"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt, size, **options):
        return box.make_structure(dt, size, **options)

    def random_params(self, structure, rng):
        """Drawn in the fit's coordinates (``fit.py``), which keep Kuhnen's invertibility
        condition: loading slopes ``V_i`` and ``S^-1`` slopes log-uniform in ``[MIN_SLOPE,
        1 / MIN_SLOPE] = [0.01, 100]``, split creep weights ``w+, w-`` uniform in ``[0, 1]``,
        offset ``b`` in ``[-1, 1]``, ``S^-1`` thresholds of an output range ``[-1, 1]``, either
        polarity. Bounded: ``|y| <= sum |w_S| (sum |w_H| + sum |w_K| + |b|) max(1, |u|)``."""
        return box.random_params(structure, rng)

    def at(self, structure, dt):
        """The same continuous-time model sampled every ``dt``.

        The plays and dead zones are rate independent. The creep operators are
        ``dz/dt = a (x - z)`` with rates ``a_j`` in 1/s, discretised exactly for an input held
        over a sample: their gains ``c_j = 1 - exp(-a_j dt)`` (``PiStructure.creep_gains``) are
        derived from ``dt``, so replacing ``dt`` re-discretises them. For a held (ZOH) input
        the model at ``dt / k`` gives the same output at the common instants.
        """
        return dataclasses.replace(structure, dt=float(dt))

    def block(self, structure, params, inverse=False):
        pi.simulate(structure, params, np.zeros(2))  # checks that params fit the structure
        head = [structure.n_play, structure.n_creep, params.d_s.size]
        r, c = np.asarray(structure.play_thresholds), structure.creep_gains
        if not inverse:
            body = np.concatenate([head, [params.b], r, params.w_h, c, params.w_k, params.d_s,
                                   params.w_s])
            return Block(kernels.block_forward, np.ascontiguousarray(body, dtype=np.float64),
                         structure.n_play + structure.n_creep)
        reason = pi.not_invertible_reason(structure, params)
        if reason:
            raise FitDivergedError(f"the model has no inverse: {reason}")
        sign, w_inst, r_inv, w_inv, d_inv, ws_inv = pi.inverse_parts(structure, params)
        # as model.invert: the kernel inverts sign * H~, so the right-hand side gets the sign
        body = np.concatenate([head, [sign * params.b], r, params.w_h, c, sign * params.w_k,
                               d_inv, sign * ws_inv, r_inv, w_inv, sign * w_inst])
        return Block(kernels.block_inverse, np.ascontiguousarray(body, dtype=np.float64),
                     structure.n_play + structure.n_creep)

    def linearise(self, structure, params, x, u, inverse=False):
        """Jacobian of one step, analytical.

        A play moves with the input when the input is at or beyond the edge of its band
        (``|u - p| >= r``: one-sided in the direction of the last change, which put the play
        on that edge) -- ``dp+/du = 1``, ``dp+/dp = 0`` -- and is frozen strictly inside it
        (``0``, ``1``: memory, an eigenvalue 1 that the input cannot reach). Creep states give
        ``1 - c`` and ``c``. ``S'`` is the dead-zone slope at ``H + K + b``, the mean of the two
        slopes exactly on a threshold. The inverse follows from the forward Jacobian at the
        estimate ``u_hat``: ``du = (dy - C dx) / D``.
        """
        x = np.asarray(x, dtype=float)
        if inverse:
            u = pi.invert_step(structure, params, x, u)[0]
        n = structure.n_play
        r, c = np.asarray(structure.play_thresholds), structure.creep_gains
        moving = (np.abs(u - x[:n]) >= r).astype(float)
        y_next = pi.step(structure, params, x, u)[1]
        v = params.w_h @ y_next[:n] + params.w_k @ y_next[n:] + params.b
        d_s, w_s = params.d_s, params.w_s
        active = np.where(d_s > 0, np.sign(v - d_s) + 1, np.where(d_s < 0, 1 - np.sign(v - d_s),
                                                                  2.0)) / 2
        s_slope = float(w_s @ active)
        a = np.diag(np.concatenate([1.0 - moving, 1.0 - c]))
        b = np.concatenate([moving, c])
        cc = s_slope * np.concatenate([params.w_h * (1.0 - moving), params.w_k * (1.0 - c)])
        d = s_slope * float(params.w_h @ moving + params.w_k @ c)
        if not inverse:
            return a, b, cc, d
        return a - np.outer(b, cc) / d, b / d, -cc / d, 1.0 / d


FAMILY = PiFamily()
