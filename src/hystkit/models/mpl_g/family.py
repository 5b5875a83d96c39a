"""The ch. 7 compensator family (sec. 7.2: sinh cells, eq. 5.1-5.6, with a cubic output
resistor, eq. 5.16-5.17) behind the family protocol."""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._capabilities import ALL_LOSSES, Capabilities
from .._cells import Cells, cell_reductions, cell_report
from .._cubic_output import output_linearisation
from .._protocol import Block, Family, FitStart
from ..mpl.family import FAMILY as MPL
from ..mpl.kernels import current
from ..mpl_poly.presets import PAPER_9_2_TABLE_II
from . import INFO, fit, kernels
from . import model as mpl_g
from .export import TRANSLATION
from .presets import ch7_compensator

__all__ = ["FAMILY", "MplGFamily"]


class MplGFamily(Family):
    """The ch. 7 compensator (sec. 7.2: sinh cells with a cubic output resistor) as a registered
    family.
    """

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = mpl_g.MplGStructure
    Params = mpl_g.MplGParams
    model = mpl_g  # step, simulate, invert, rest_state
    # the gauge fixes w_0 = 1, so a weight-sum bound must exceed 1
    capabilities = Capabilities(losses=ALL_LOSSES, weight_sum_floor=mpl_g.WEIGHT_SUM_FLOOR,
                                start_from_params=True)

    fit_function = fit.fit_mpl_g

    def invert_step(self, structure, params, x, y):
        """As :func:`model.invert_step`; NaN input estimate and state when ``y`` is outside
        the range of ``g``'s branch (no input gives it), as the compiled block."""
        if not mpl_g._solve(params, y)[1]:
            return np.nan, np.full(np.size(x), np.nan)
        return mpl_g.invert_step(structure, params, x, y)

    def make_structure(self, dt: float, size: int, slope_cap: float = 1.0) -> mpl_g.MplGStructure:
        return self.Structure(n_cells=size, dt=dt, slope_cap=slope_cap)

    def at(self, structure, dt):
        """Same cells and slope cap at ``dt``: ``I_S``, ``V_T`` and ``g`` are those of a
        continuous ODE and a memoryless output; only the Euler knees (``f' = slope_cap / dt``)
        follow ``dt``, and they are computed from it."""
        return super().at(structure, dt)

    def random_params(self, structure, rng):
        """:func:`.fit.random_params`: ``G_k`` log-uniform in ``[1e-4, slope_cap / dt]``,
        ``V_T`` log-uniform in ``[1e-3, 1e3]``, an increasing cubic ``g`` (``g_1`` in
        ``[0.1, 2]``, ``g_3`` in ``[0.01, 2]``, ``g_2^2 < 3 g_1 g_3``, ``|g_0| <= 2``),
        ``0.5 <= |w_0| <= 2``, ``sum |w_k| < 0.9 |w_0|``, ``|V_b| <= 1``. The output is bounded
        (``|y| <= sum_j |g_j| Z^j``, ``Z = sum |w| max|u| + |V_b|``), and with
        ``slope_cap <= 1`` the inverse exists for every output and contracts."""

        return fit.random_params(structure, rng)

    def start_options(self, structure, params):
        """``init=params`` for :func:`.fit.fit_mpl_g` (a single start, in its gauge ``w_0 = 1``,
        ``V_b = 0``), with a note for every coordinate outside the fit's box."""
        lower, upper = fit.fit_box(structure)
        return FitStart.in_box({"init": params}, fit.start_theta(params), lower, upper,
                               fit.theta_names(structure.n_cells))

    def presets(self):
        """The sec. 7.2 compensators of paper 9.2's table II sensors, ``ch7-table-ii-COLUMN``,
        fitted on first use (about 1-3 s each; :mod:`.presets` says why table II's own weights
        cannot be presets of this family)."""
        return {f"ch7-table-ii-{column}": ch7_compensator(column)
                for column in PAPER_9_2_TABLE_II}

    def n_params(self, structure, params) -> int:
        """``3N + 4``: ``w_0`` and ``V_b`` are the gauge of ``g``'s voltage (``fit.canonical``),
        fixed at 1 and 0 by the fit, so they count for no information criterion."""
        return 3 * structure.n_cells + 4

    def fixed_params(self, structure, params) -> tuple[str, ...]:
        """``w[0]`` and ``v_b``: the fit works in the gauge ``w_0 = 1``, ``V_b = 0``
        (``fit.fit_mpl_g``), so the data determine neither."""
        return ("w[0]", "v_b")

    def reductions(self, structure, params):
        """Each cell dropped, and merged into each other one (:func:`.._cells.cell_reductions`);
        ``g`` and the gauge ``w_0``, ``V_b`` are kept."""
        return cell_reductions(structure, params)

    def block(self, structure, params, inverse=False):
        if inverse:
            if params.w[0] == 0:
                raise FitDivergedError("the model has w_0 = 0, so it has no inverse (eq. 5.13)")
            branch = mpl_g.inverse_branch(params)
        else:  # the forward model needs no branch (g may have none through the rest point)
            branch = (-np.inf, np.inf, 0.0, 0.0)
        body = np.concatenate([[params.n_cells, params.v_b, structure.slope_cap / structure.dt,
                                structure.dt, 1.0], branch, params.g, params.i_s, params.v_t,
                               mpl_g.knee_voltage(structure, params), params.w])
        step = kernels.block_inverse if inverse else kernels.block_forward
        return Block(step, np.ascontiguousarray(body, dtype=np.float64), structure.n_cells)

    def linearise(self, structure, params, x, u, inverse=False):
        """Paper 9.2 eq. 2-7. Forward: ``dx+ = (1 - f' dt) dx + f' dt du``,
        ``dy = g'(z) (w_0 du + w . dx)``. Inverse: ``dz = dy / g'(z)``,
        ``de = (dz - w . dx) / w_0``, the cells driven by ``e``. ``f'`` is the slope of the
        limited sinh resistor (eq. 5.29) at the operating point."""
        knee = mpl_g.knee_voltage(structure, params)
        cap = structure.slope_cap / structure.dt

        def cell_slopes(v):
            return np.array([current(v[k], params.i_s[k], params.v_t[k], knee[k], cap)[1]
                             for k in range(structure.n_cells)])

        return output_linearisation(structure, params, x, u, inverse,
                                    lambda y: mpl_g._solve(params, y), mpl_g.output_slope,
                                    cell_slopes)

    def cells(self, structure, params) -> Cells:
        """The model as the eq. 5.18-5.28 analysis sees it (sinh cells, cubic output ``g``)."""
        sinh = MPL.cells(structure, params)  # duck-typed: the cells read i_s, v_t, w, v_b
        return Cells(current=sinh.current, slope=sinh.slope,
                     output=lambda z: mpl_g.output_current(params, z),
                     output_slope=lambda z: mpl_g.output_slope(params, z), w=params.w,
                     v_b=params.v_b, dt=structure.dt, knees=sinh.knees,
                     rest_points=sinh.rest_points,
                     start=lambda e0: np.full(structure.n_cells, e0),
                     check=lambda u: mpl_g.simulate(structure, params, u))

    def stability_details(self, structure, params, u):
        """eq. 5.28 per cell at every rest point and along a run on ``u`` (``_cells``)."""
        return cell_report(self.cells(structure, params), u)


FAMILY = MplGFamily()
