"""The modified Power-Law family (sec. 5.3.1, eq. 5.1-5.6) behind the family protocol."""

from __future__ import annotations

import dataclasses

import numpy as np

from .._capabilities import ALL_LOSSES, Capabilities
from .._cells import Cells, cell_reductions, cell_report
from .._protocol import Block, Family, FitStart
from . import INFO, kernels
from . import model as mpl
from .box import fit_box, random_params, theta_names
from .export import TRANSLATION
from .presets import PRESETS, preset

__all__ = ["FAMILY", "MplFamily"]


class MplFamily(Family):
    """The modified Power-Law model with sinh resistors (sec. 5.3.1) as a registered family."""

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = mpl.MplStructure
    Params = mpl.MplParams
    model = mpl  # step, simulate, invert, invert_step
    capabilities = Capabilities(losses=ALL_LOSSES, weight_sum_floor=0.0, linear_output=True,
                                start_from_params=True)

    fit_function = "fit.fit_mpl"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt: float, size: int, slope_cap: float = 1.0,
                       limit: bool = True) -> mpl.MplStructure:
        return self.Structure(n_cells=size, dt=dt, slope_cap=slope_cap, limit=limit)

    def presets(self):
        """The reference document's one-cell sets (:mod:`.presets`): ``table-5.2`` (initial
        conditions), ``table-5.2-fitted`` (its fmincon result, unlimited sinh) and
        ``paper-9.1`` (initial conditions), normalised units, at 40 Hz."""
        return {name: preset(name, limit=name != "table-5.2-fitted") for name in PRESETS}

    def start_options(self, structure, params):
        """``init=params`` for :func:`.fit.fit_mpl` (a single start, no linear initialisation
        of the weights), with a note for every coordinate outside the fit's box."""
        lower, upper = fit_box(structure)
        return FitStart.in_box({"init": params}, params.to_vector(), lower, upper,
                               theta_names(structure.n_cells))

    def random_params(self, structure, rng):
        """The fit's box (:func:`.fit.fit_mpl`), normalised data: ``G_k = 2 I_S / V_T`` log-uniform
        in ``[1e-4, slope_cap / dt]``, ``V_T`` log-uniform in ``[1e-3, 1e3]``, ``w`` and ``V_b``
        uniform in ``[-100, 100]``. Every draw is bounded: ``|y| <= sum |w| max|u| + |V_b|``."""
        return random_params(structure, rng)

    def reductions(self, structure, params):
        """Each cell dropped, and merged into each other one (:func:`.._cells.cell_reductions`)."""
        return cell_reductions(structure, params)

    def block(self, structure, params, inverse=False):
        body = np.concatenate([[params.n_cells, params.v_b, structure.slope_cap / structure.dt,
                                structure.dt], params.i_s, params.v_t,
                               mpl.knee_voltage(structure, params), params.w])
        step = kernels.block_inverse if inverse else kernels.block_forward
        return Block(step, np.ascontiguousarray(body, dtype=np.float64), structure.n_cells)

    def linearise(self, structure, params, x, u, inverse=False):
        """Paper 9.2 eq. 2-7: each cell ``x+ = x + f(v) dt`` becomes
        ``dx+ = (1 - f' dt) dx + f' dt d(drive)``, ``f'`` the slope of the limited resistor
        (eq. 5.29) at the operating point; the inverse's drive ``(u - w.x + V_b) / w_0`` feeds
        back into every cell."""
        x = np.asarray(x, dtype=float)
        knee = mpl.knee_voltage(structure, params)
        cap = structure.slope_cap / structure.dt
        w, w0 = params.w[1:], params.w[0]
        drive = (u + params.v_b - w @ x) / w0 if inverse else u
        slope = np.array([kernels.current(drive - x[k], params.i_s[k], params.v_t[k], knee[k],
                                          cap)[1] for k in range(structure.n_cells)])
        g = slope * structure.dt
        if inverse:
            return np.diag(1.0 - g) - np.outer(g, w) / w0, g / w0, -w / w0, 1.0 / w0
        return np.diag(1.0 - g), g, w.copy(), float(w0)

    def cells(self, structure, params) -> Cells:
        """The model as the eq. 5.18-5.28 analysis sees it (linear output ``g(z) = z``). Without
        the limit the resistor is the sinh everywhere; the knees reported are still where
        ``f' dt`` reaches the slope cap (where the limit would act), as mpl-poly's."""
        knee = mpl.knee_voltage(structure, params)
        limited = structure  # mpl-g's structure, which reuses these cells, has no limit field
        if not getattr(structure, "limit", True):
            limited = dataclasses.replace(structure, limit=True)
        shown = mpl.knee_voltage(limited, params)
        cap = structure.slope_cap / structure.dt
        g = 2 * params.i_s / params.v_t

        def slope(v):  # G cosh(v / V_T) inside the knee, the cap beyond
            v = np.asarray(v, dtype=float)
            inside = np.abs(v) <= knee
            return np.where(inside, g * np.cosh(np.where(inside, v, 0.0) / params.v_t), cap)

        return Cells(current=lambda v: mpl.resistor_current(structure, params, v), slope=slope,
                     output=lambda z: z, output_slope=lambda z: 1.0, w=params.w,
                     v_b=params.v_b, dt=structure.dt, knees=np.column_stack([-shown, shown]),
                     rest_points=[np.zeros(1)] * structure.n_cells,  # sinh: odd, monotone
                     start=lambda e0: np.full(structure.n_cells, e0),
                     check=lambda u: mpl.simulate(structure, params, u))

    def stability_details(self, structure, params, u):
        return cell_report(self.cells(structure, params), u)


FAMILY = MplFamily()
