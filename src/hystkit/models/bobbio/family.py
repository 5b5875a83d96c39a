"""The Bobbio-Marrucci family (sec. 2.1.4, eq. 2.5) behind the family protocol."""

from __future__ import annotations

import numpy as np

from .._protocol import Block, Family
from . import INFO, kernels
from . import model as bobbio
from .export import TRANSLATION

__all__ = ["FAMILY", "BobbioFamily"]


class BobbioFamily(Family):
    """The Bobbio-Marrucci spring/piston chain (sec. 2.1.4) as a registered family."""

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = bobbio.BobbioStructure
    Params = bobbio.BobbioParams
    model = bobbio

    fit_function = "fit.fit_bobbio"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt: float, size: int) -> bobbio.BobbioStructure:
        return bobbio.BobbioStructure(n_springs=size, dt=dt)

    def random_params(self, structure, rng):
        """The fit's domain (``fit.py``): compliances ``>= 0`` (Dirichlet-spread, total
        log-uniform in ``[0.1, 10]``), piston thresholds ``a_k > 0`` whose largest play radius
        ``A_N-1 = sum a_k`` is log-uniform in the fit's ``[0.1, 1.5]`` times the input's
        half-range 1 (each ``a_k >= 0.1 A_N-1 / (N - 1)``), offset in ``[-1, 1]``. Bounded:
        every spring force is a play of ``u``, so ``|y| <= sum c_k max|u| + |b|``."""
        n = structure.n_springs
        compliance = np.exp(rng.uniform(np.log(0.1), np.log(10.0))) * rng.dirichlet(np.ones(n))
        m = n - 1
        radius = np.exp(rng.uniform(np.log(0.1), np.log(1.5)))
        friction = (radius * (0.1 / m + 0.9 * rng.dirichlet(np.ones(m))) if m
                    else np.empty(0))
        return bobbio.BobbioParams(compliance=compliance, friction=friction,
                                   offset=rng.uniform(-1.0, 1.0))

    def at(self, structure, dt):
        """The chain is rate-independent (only the input values matter, not their timing), so
        the same model runs at any ``dt``; only the recorded ``dt`` changes."""
        return super().at(structure, dt)

    def block(self, structure, params, inverse=False):
        body = np.concatenate([[params.n_springs, params.offset], params.compliance,
                               params.friction])
        step = kernels.block_inverse if inverse else kernels.block_forward
        return Block(step, np.ascontiguousarray(body, dtype=np.float64),
                     structure.n_springs - 1)

    def linearise(self, structure, params, x, u, inverse=False):
        """A sliding piston passes the force before it on (``dF_k+1 = dF_k``), a sticking one
        keeps its own (``dF_k+1 = dF_k+1``); ``y = c_1 u + sum c_k F_k + b``. The inverse solves
        that output for ``u`` at the operating point's force, ``du = (dy - C dx) / D``: the
        derivative along the motion the chain is making there (where ``D = 0``, a flat
        segment, the numerical default is used). A piston exactly on its threshold (where
        sliding stopped) is a kink; it counts as sticking."""
        x = np.asarray(x, dtype=float)
        m = x.size
        u_op = bobbio.invert_step(structure, params, x, u)[0] if inverse else u
        # rows of d(x+) / d(x, u): column m is the input
        rows = np.zeros((m, m + 1))
        prev_row, prev = np.eye(1, m + 1, m)[0], u_op
        for k in range(m):
            a = params.friction[k]
            sliding = x[k] < prev - a or x[k] > prev + a
            rows[k] = prev_row if sliding else np.eye(1, m + 1, k)[0]
            prev_row, prev = rows[k], min(max(x[k], prev - a), prev + a)
        a_mat, b = rows[:, :m], rows[:, m]
        c = params.compliance[1:] @ a_mat
        d = float(params.compliance[0] + params.compliance[1:] @ b)
        if not inverse:
            return a_mat, b, c, d
        if d == 0:
            return super().linearise(structure, params, x, u, inverse=True)
        return a_mat - np.outer(b, c) / d, b / d, -c / d, 1.0 / d


FAMILY = BobbioFamily()
