"""The exported mpl-g C advances its cells with the mPL's exported cell code (issue 29, item 2):
per-cell constants fixed at export, one exp per cell; in double with ``-ffp-contract=off`` the
generated ``model_step`` gives ``mpl_g.kernels``' run bit for bit, forward and inverse, inside
and beyond the knee and on nearly linear cells (as ``test_export_mpl_cell_constants.py``)."""

from __future__ import annotations

import numpy as np
from numpy.testing import assert_array_equal

from hystkit.compensation import Compensator, LinearBaseline
from hystkit.compensation._conventions import Scaling
from hystkit.export import c_files, make_plan
from hystkit.models.mpl import kernels as mpl_kernels
from hystkit.models.mpl_g import kernels, model

from .export_support import model_steps_in_c

DT = 0.025
# Cell 1 crosses its knee on the noise; cells 2 and 3 are nearly linear (V_T ~ 1e3, |a| < 0.5:
# the series), with large opposite weights; g' > 0 everywhere (one branch, no bound).
PARAMS = model.MplGParams(i_s=[0.05, 2500.0, 1800.0], v_t=[0.2, 1000.0, 900.0],
                          g=[0.0, 1.0, 0.05, 0.02], w=[1.0, 0.5, 20.0, -20.0], v_b=0.1)
STRUCTURE = model.MplGStructure(n_cells=3, dt=DT)



def _compensator(mode: str) -> Compensator:
    return Compensator(structure=STRUCTURE, params=PARAMS, mode=mode, center="fit",
                       scaling=Scaling(0.0, 1.0, 0.0, 1.0), baseline=LinearBaseline(1.0, 0.0),
                       model="mpl-g", training_range=(-1.5, 1.5), position_range=(-1.5, 1.5))


def _input(n: int = 3000) -> np.ndarray:
    t = np.arange(n) * DT
    return np.sin(0.5 * t) + 0.2 * np.random.default_rng(3).standard_normal(n)


def _cell_args():
    return (PARAMS.i_s, PARAMS.v_t, model.knee_voltage(STRUCTURE, PARAMS),
            STRUCTURE.slope_cap / DT, DT)


def test_exported_forward_step_is_the_kernel_run_bit_for_bit(tmp_path):
    u = _input()
    knee = model.knee_voltage(STRUCTURE, PARAMS)
    # cell 1's voltage leaves its knee (the straight branch runs): its state, as the output of
    # a one-cell mPL with w = [0, 1], lags the input by more than the knee somewhere
    x1, _ = mpl_kernels.simulate(u, np.full(1, u[0]), PARAMS.i_s[:1], PARAMS.v_t[:1],
                                 np.array([0.0, 1.0]), 0.0, knee[:1], STRUCTURE.slope_cap / DT,
                                 DT)
    assert np.max(np.abs(u - x1)) > knee[0]
    y, _ = kernels.simulate(u, np.full(3, u[0]), PARAMS.g, PARAMS.w, PARAMS.v_b, *_cell_args())
    assert_array_equal(model_steps_in_c(tmp_path, _compensator("direct"), u), y)


def test_exported_inverse_step_is_the_kernel_inversion_bit_for_bit(tmp_path):
    y_in = _input()
    x0 = model.rest_state(STRUCTURE, PARAMS, y_in[0], inverse=True)
    bound = 1e6 * (1.0 + np.max(np.abs(y_in)) + np.max(np.abs(x0)))
    e_hat, _, n_bad, _ = kernels.invert(y_in, x0, PARAMS.g, *model.inverse_branch(PARAMS),
                                        PARAMS.w, PARAMS.v_b, *_cell_args(), bound)
    assert n_bad == -1
    assert_array_equal(model_steps_in_c(tmp_path, _compensator("inverse"), y_in), e_hat)


def test_export_has_no_libm_sinh_per_sample():
    """The per-sample step calls no sinh (constants fixed at export, one exp per cell)."""
    source = c_files(make_plan(_compensator("direct"), name="mplg"), double=True)["mplg.c"]
    step = source[source.index("static real sinh_one_exp"):]
    assert "SINH(" not in step and "EXP(" in step
