"""The Chua-Stromsmoe family (sec. 2.1.3, eq. 2.3) behind the family protocol."""

from __future__ import annotations

import numpy as np

from .._capabilities import ALL_LOSSES, Capabilities
from .._euler_cap import at_same_limit
from .._protocol import Block, Family
from . import INFO, box, kernels
from . import model as chua
from .export import TRANSLATION

__all__ = ["FAMILY", "ChuaFamily"]


class ChuaFamily(Family):
    """The Chua-Stromsmoe model (sec. 2.1.3) as a registered family."""

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = chua.ChuaStructure
    Params = chua.ChuaParams
    model = chua
    capabilities = Capabilities(losses=ALL_LOSSES)

    fit_function = "fit.fit_chua"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt: float, size: int, slope_cap: float = 1.0) -> chua.ChuaStructure:
        return chua.ChuaStructure(n_elements=size, dt=dt, slope_cap=slope_cap)

    def random_params(self, structure, rng):
        """The fit's bounds (:func:`.box.random_params`): ``k_0``, ``k_inf``, ``y_s`` log-uniform in
        ``[1e-2, 1e2]``, ``G`` in ``[1e-3, 100 / dt]``, ``V_g`` in ``[1e-3, 1e3]``, ``delta`` in
        ``[0, 1]``. Bounded: ``|y| <= sum_k (max|u| + delta_k) / min(k_0, k_inf)_k``."""
        return box.random_params(structure, rng)

    def at(self, structure, dt):
        """The same ODE at ``dt``: the slope cap scales with ``dt``, so the limit on ``g'``
        (``slope_cap / (dt max(k_0, k_inf))``, in 1/s) and hence the limited ``g`` the model
        was fitted with stay what they were. The relative cap saturates at
        ``max(slope_cap, 1)``: at a coarser step that needs more, the Euler step stays monotone
        (stable, no overshoot) and the absolute limit falls instead, so the fastest part of
        ``g`` becomes slower than fitted."""
        return at_same_limit(structure, dt)

    def block(self, structure, params, inverse=False):
        *per_element, dt = chua.kernel_args(structure, params)
        body = np.concatenate([[params.n_elements, dt], *per_element])
        step = kernels.block_inverse if inverse else kernels.block_forward
        return Block(step, np.ascontiguousarray(body, dtype=np.float64), structure.n_elements)

    def linearise(self, structure, params, x, u, inverse=False):
        """Each element ``x+ = x + dt g(u - f(x))`` gives ``dx+ = (1 - dt g' f') dx + dt g' du``
        and the output ``y = sum x+``. The inverse solves that output for ``u`` at the
        operating point's input ``u_hat``: ``du = (dy - C dx) / D``; where no element moves
        (``D = 0``, dead bands) it has no derivative and the numerical default is used."""
        x = np.asarray(x, dtype=float)
        u_op = chua.invert_step(structure, params, x, u)[0] if inverse else u
        fx_slope = params.k_inf + (params.k0 - params.k_inf) / np.cosh(x / params.y_s) ** 2
        v = u_op - chua.restoring(params, x)
        b = structure.dt * chua.dissipation_slope(structure, params, v)
        a = np.diag(1.0 - b * fx_slope)
        c, d = a.sum(axis=0), float(b.sum())
        if not inverse:
            return a, b, c, d
        if d == 0:
            return super().linearise(structure, params, x, u, inverse=True)
        return a - np.outer(b, c) / d, b / d, -c / d, 1.0 / d


FAMILY = ChuaFamily()
