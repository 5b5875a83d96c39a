"""The PWL ladder family (Parodi-Storace-Cincotti, sec. 2.1.5) behind the family protocol."""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._capabilities import ALL_LOSSES, Capabilities
from .._euler_cap import at_same_limit
from .._protocol import Block, Family
from . import INFO, box, kernels
from . import model as ladder
from .export import TRANSLATION

__all__ = ["FAMILY", "LadderFamily"]


class LadderFamily(Family):
    """The PWL ladder circuit (sec. 2.1.5) as a registered family."""

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = ladder.LadderStructure
    Params = ladder.LadderParams
    model = ladder
    # the largest play threshold (eq. 2.21) is the sum of the bands
    capabilities = Capabilities(
        losses=ALL_LOSSES, linear_output=True,
        sync_amplitude=lambda structure, params: float(np.sum(params.band)))

    fit_function = "fit.fit_ladder"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt: float, size: int,
                       slope_cap: float = 1.0) -> ladder.LadderStructure:
        return ladder.LadderStructure(n_cells=size, dt=dt, slope_cap=slope_cap)

    def random_params(self, structure, rng):
        """The fit's bounds (:func:`.box.random_params`): ``E_k`` in ``[0, 1.5]``, ``G_k``
        log-uniform in ``[1e-3, slope_cap / (2 dt)]``, ``w``, ``V_b`` in ``[-100, 100]``.
        Bounded: ``|y| <= sum |w| max|e| + |V_b|``."""
        return box.random_params(structure, rng)

    def at(self, structure, dt):
        """The same circuit at ``dt``: the slope cap scales with ``dt``, so the conductance
        limit ``slope_cap / (2 dt)`` [1/s], and with it every effective ``G_k``, stays what
        the model was fitted with (the fit bounds ``G_k`` by that limit). The relative cap
        saturates at ``max(slope_cap, 1)``: at a coarser step that needs more, the Euler step
        stays monotone and the limit falls instead, so the fastest sections lag more than
        fitted."""
        return at_same_limit(structure, dt)

    def block(self, structure, params, inverse=False):
        if inverse and params.w[0] == 0:
            raise FitDivergedError("the ladder model has w_0 = 0, so it has no inverse")
        body = np.concatenate([[params.n_cells, params.v_b, structure.dt], params.band,
                               ladder.effective_conductance(structure, params), params.w])
        step = kernels.block_inverse if inverse else kernels.block_forward
        return Block(step, np.ascontiguousarray(body, dtype=np.float64), structure.n_cells)

    def linearise(self, structure, params, x, u, inverse=False):
        """Section ``k`` conducts (``|U_k-1 - U_k| > E_k``) or not; a conducting one passes
        ``di_k = G_k (dU_k-1 - dU_k)``, and ``dU_k+ = dU_k + dt (di_k - di_k+1)``;
        ``y = w_0 e + w . U - V_b``. The inverse's ``e = (y + V_b - w . U) / w_0`` feeds back
        into the first section. On a band edge (a kink) the section counts as blocking."""
        x = np.asarray(x, dtype=float)
        n = x.size
        w0, w = params.w[0], params.w[1:]
        e = (u + params.v_b - w @ x) / w0 if inverse else u
        v = np.concatenate([[e], x[:-1]]) - x
        g = ladder.effective_conductance(structure, params) * (np.abs(v) > params.band)
        di = np.zeros((n, n + 1))  # d i_k / d(U_1..U_N, e): U_0 = e is column n
        for k in range(n):
            di[k, k] -= g[k]
            di[k, k - 1 if k else n] += g[k]
        jac = np.hstack([np.eye(n), np.zeros((n, 1))]) + structure.dt * (
            di - np.vstack([di[1:], np.zeros((1, n + 1))]))
        a, b = jac[:, :n], jac[:, n]
        if inverse:
            return a - np.outer(b, w) / w0, b / w0, -w / w0, 1.0 / w0
        return a, b, w.copy(), float(w0)


FAMILY = LadderFamily()
