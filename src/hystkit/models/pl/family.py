"""The Power-Law family as published (sec. 2.1.7, eq. 2.16-2.18) behind the family protocol."""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._capabilities import ALL_LOSSES, Capabilities
from .._protocol import Block, Family
from . import INFO, box, kernels
from . import model as pl
from .export import TRANSLATION

__all__ = ["FAMILY", "PlFamily"]


class PlFamily(Family):
    """The Power-Law model of hysteresis and creep (sec. 2.1.7) as a registered family."""

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = pl.PlStructure
    Params = pl.PlParams
    model = pl
    # linear output: f(i) = a_1 i with a_1 = M = 1 for one output segment; synchronisation:
    # eq. 2.21 with E_0 = N V_T, the largest play threshold
    capabilities = Capabilities(
        losses=ALL_LOSSES, linear_output=lambda structure: structure.n_basis == 1,
        sync_amplitude=lambda structure, params: structure.n_cells * params.v_t)

    fit_function = "fit.fit_pl"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt: float, size: int, power: float = 21.0, n_basis: int = 1,
                       smoothing: float = 0.001, slope_cap: float = 1.0) -> pl.PlStructure:
        return pl.PlStructure(n_cells=size, power=power, n_basis=n_basis, smoothing=smoothing,
                              dt=dt, slope_cap=slope_cap)

    def random_params(self, structure, rng):
        """The fit's bounds (:func:`.box.random_params`): ``I_T`` log-uniform in ``[1e-6, 1e4]``,
        ``V_T`` in ``[1e-3, 2]``, ``w``, ``V_b`` in ``[-100, 100]``, ``a_j >= 0.05`` with
        ``sum a_j = M``. Bounded: ``|y| <= (sum |w| max|e| + |V_b|) / min a_j``."""
        return box.random_params(structure, rng)

    def at(self, structure, dt):
        """Same N, p, M, S and slope cap at ``dt``. ``I_T``, ``V_T`` are rates and voltages of
        the continuous cells (``du_k/dt = d_k``), so they stay; the straight branches' slope
        ``G = slope_cap / dt`` is the Euler limit and follows ``dt``, so a cell driven beyond
        its threshold still follows the input within one sample (the play-operator part), and
        the knees are recomputed from it."""
        return super().at(structure, dt)

    def block(self, structure, params, inverse=False):
        if inverse and params.w[0] == 0:
            raise FitDivergedError("the model has w_0 = 0, so it has no inverse (eq. 2.20)")
        i_t, thr, knee, power, g_lin, dt = pl.kernel_args(structure, params)
        body = np.concatenate([[params.n_cells, params.n_basis, i_t, power, g_lin, dt,
                                params.v_b], thr, knee, params.w,
                               pl.basis_breakpoints(params.n_basis), params.a])
        step = kernels.block_inverse if inverse else kernels.block_forward
        return Block(step, np.ascontiguousarray(body, dtype=np.float64), structure.n_cells)

    def linearise(self, structure, params, x, u, inverse=False):
        """Each cell ``x+ = x + d(drive - x) dt`` gives ``dx+ = (1 - d' dt) dx + d' dt
        d(drive)``, ``d'`` the slope of the cell resistor (power law or straight branch).
        Forward: ``di = (w_0 de + w . dx) / f'(i)``; inverse: ``de = (f'(i) di - w . dx) / w_0``,
        the cells driven by ``e``. ``f'`` is the slope ``a_j`` of the output resistor's segment
        (on a breakpoint the left one; the numerical default would average the two)."""
        x = np.asarray(x, dtype=float)
        w0, w = params.w[0], params.w[1:]
        if inverse:
            a = float(pl.output_resistor_slope(params, u))
            drive = pl.invert_step(structure, params, x, u)[0]
        else:
            i = pl.output_resistor_inverse(params, w0 * u + w @ x - params.v_b)
            a = float(pl.output_resistor_slope(params, i))
            drive = u
        g = pl.resistor_slope(structure, params, drive - x) * structure.dt
        if inverse:
            return np.diag(1.0 - g) - np.outer(g, w) / w0, g * a / w0, -w / w0, a / w0
        return np.diag(1.0 - g), g, w / a, float(w0 / a)


FAMILY = PlFamily()
