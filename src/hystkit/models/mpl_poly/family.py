"""The polynomial mPL family (sec. 5.3.5, eq. 5.16-5.17, 5.29; paper 9.2) behind the protocol."""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._capabilities import ALL_LOSSES, Capabilities
from .._cells import Cells, cell_report
from .._cubic_output import output_linearisation
from .._protocol import Block, Family, FitStart
from . import INFO, fit, kernels
from . import model as mpl_poly
from .export import TRANSLATION
from .presets import PAPER_9_2_TABLE_I, PAPER_9_2_TABLE_II, paper_9_2_params
from .rest import solve_on_branch

__all__ = ["FAMILY", "MplPolyFamily"]


class MplPolyFamily(Family):
    """The polynomial modified Power-Law model (sec. 5.3.5, paper 9.2) as a registered family."""

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = mpl_poly.MplPolyStructure
    Params = mpl_poly.MplPolyParams
    model = mpl_poly
    # no weight_sum_max: the output resistor's gauge (z -> alpha z, g re-expanded) gives every
    # model an equivalent one with sum |w| below any bound, so the constraint restricts nothing
    capabilities = Capabilities(losses=ALL_LOSSES, start_from_params=True)

    fit_function = fit.fit_mpl_poly

    def n_params(self, structure, params) -> int:
        """``4N + 4``: of the ``5N + 6`` stored numbers, ``c_k0``, ``w_0`` and ``V_b`` are the
        gauge (:func:`.fit.canonical`), so they count for no information criterion."""
        return 4 * structure.n_cells + 4

    def fixed_params(self, structure, params) -> tuple[str, ...]:
        """``f[k][0]`` of every cell, ``w[0]`` and ``v_b``: the fit maps its result to the
        gauge ``v*_k = 0`` (so ``c_k0 = 0`` while the rest point is on the cubic), ``w_0 = 1``,
        ``V_b = 0`` (:func:`.fit.canonical`); the data determine none of them."""
        return (*(f"f[{k}][0]" for k in range(structure.n_cells)), "w[0]", "v_b")

    def make_structure(self, dt: float, size: int, slope_cap: float = 1.0,
                       limit: bool = True) -> mpl_poly.MplPolyStructure:
        return mpl_poly.MplPolyStructure(n_cells=size, dt=dt, slope_cap=slope_cap, limit=limit)

    def at(self, structure, dt):
        """Same cells, slope cap and limit at ``dt``. The cubics are rates of a continuous ODE
        (``du_k/dt = f_k``), so they do not depend on the step; only the Euler limit does, and
        the knees (``f' = slope_cap / dt``) follow ``dt`` because they are computed from it."""
        return super().at(structure, dt)

    def random_params(self, structure, rng):
        """Paper 9.2's published range with margin (:func:`.fit.random_params`): ``c_k0..c_k2``
        in ``[-5, 5]``, ``c_k3`` log-uniform in ``[0.1, 100]``, ``g``, ``w`` in ``[-2, 2]``,
        ``V_b`` in ``[-1, 1]``. Bounded with ``structure.limit``: ``|u_k| <= max|e| + max|v*_k|``."""
        return fit.random_params(structure, rng)

    def presets(self):
        """Paper 9.2's table II columns: direct compensators (sensor -> position) fitted on
        normalised 40 Hz data, N = 1, as printed (``f2^2``, ``f3^3``); and table I, the
        initial conditions of its fits (``paper-9.2-table-i``, for ``--init``)."""
        structure = mpl_poly.MplPolyStructure(n_cells=1, dt=0.025)
        presets = {f"table-ii-{name}": (structure, paper_9_2_params(printed),
                                        {"source": f"paper 9.2 table II, {name} column (as "
                                                   "printed, f2^2, f3^3)",
                                         "direction": "sensor -> position", "fit_dt": 0.025})
                   for name, printed in PAPER_9_2_TABLE_II.items()}
        presets["paper-9.2-table-i"] = (
            structure, paper_9_2_params(PAPER_9_2_TABLE_I),
            {"source": "paper 9.2 table I, initial conditions of its fits (as printed, f2^2, "
                       "f3^3; w0, w1, V_b from the text below table II)"})
        return presets

    def start_options(self, structure, params):
        """``init=params`` for :func:`.fit.fit_mpl_poly` (a single start), with a note for
        every coordinate outside the fit's box."""
        lower, upper = fit.fit_box(structure)
        return FitStart.in_box({"init": params}, params.to_vector(), lower, upper,
                               fit.theta_names(structure.n_cells))

    def invert_step(self, structure, params, x, y):
        """As :func:`model.invert_step`; NaN input estimate and state when ``y`` is outside
        the range of ``g``'s branch (no input gives it), as the compiled block."""
        if not solve_on_branch(structure, params, y)[1]:
            return np.nan, np.full(np.size(x), np.nan)
        return mpl_poly.invert_step(structure, params, x, y)

    def block(self, structure, params, inverse=False):
        mpl_poly.check_rest(structure, params)  # the loop runs only models of the domain
        if inverse:
            if params.w[0] == 0:
                raise FitDivergedError("the model has w_0 = 0, so it has no inverse (eq. 5.13)")
            branch = mpl_poly.inverse_branch(structure, params)
        else:  # the forward model needs no branch (g may have none through the rest point)
            branch = (-np.inf, np.inf, 0.0, 0.0)
        body = np.concatenate([[params.n_cells, params.v_b, structure.slope_cap / structure.dt,
                                structure.dt, float(structure.limit)], branch, params.g,
                               params.f.reshape(-1),
                               mpl_poly.knee_points(structure, params).reshape(-1), params.w])
        step = kernels.block_inverse if inverse else kernels.block_forward
        return Block(step, np.ascontiguousarray(body, dtype=np.float64), structure.n_cells)

    def linearise(self, structure, params, x, u, inverse=False):
        """Paper 9.2 eq. 2-7. Forward: ``dx+ = (1 - f' dt) dx + f' dt du``,
        ``dy = g'(z) (w_0 du + w . dx)``. Inverse: ``dz = dy / g'(z)``,
        ``de = (dz - w . dx) / w_0``, the cells driven by ``e``. ``f'`` is the slope of the
        limited cubic (eq. 5.29) at the operating point."""
        return output_linearisation(structure, params, x, u, inverse,
                                    lambda y: solve_on_branch(structure, params, y),
                                    mpl_poly.output_slope,
                                    lambda v: mpl_poly.resistor_slope(structure, params, v))

    def cells(self, structure, params) -> Cells:
        """The model as the eq. 5.18-5.28 analysis sees it (cubic output ``g``)."""
        return Cells(current=lambda v: mpl_poly.resistor_current(structure, params, v),
                     slope=lambda v: mpl_poly.resistor_slope(structure, params, v),
                     output=lambda z: mpl_poly.output_current(params, z),
                     output_slope=lambda z: mpl_poly.output_slope(params, z), w=params.w,
                     v_b=params.v_b, dt=structure.dt,
                     knees=mpl_poly.knee_points(structure, params),
                     rest_points=mpl_poly.equilibria(structure, params),
                     start=lambda e0: mpl_poly.rest_state(structure, params, e0),
                     check=lambda u: mpl_poly.simulate(structure, params, u))

    def stability_details(self, structure, params, u):
        """eq. 5.28 per cell at every rest point and along a run on ``u`` (``_cells``)."""
        return cell_report(self.cells(structure, params), u)


FAMILY = MplPolyFamily()
