"""The exported mPL C advances its cells as ``mpl.kernels`` does (issue 29, item 2): per-cell
constants fixed at export, one exp per cell; in double with ``-ffp-contract=off`` the generated
``model_step`` gives the kernel's run bit for bit, forward and inverse, inside and beyond the
knee and on nearly linear cells (where the plain (e - 1/e) / 2 would not)."""

from __future__ import annotations

import numpy as np
from numpy.testing import assert_array_equal

from hystkit.compensation import Compensator, LinearBaseline
from hystkit.compensation._conventions import Scaling
from hystkit.export import c_files, make_plan
from hystkit.models import mpl
from hystkit.models.mpl import kernels

from .export_support import model_steps_in_c

DT = 0.025
# Cell 1 crosses its knee on the noise; cells 2 and 3 are nearly linear (V_T ~ 1e3, |a| < 0.5:
# the series), with large opposite weights (as tests/models/test_mpl_kernel_fast.py).
PARAMS = mpl.MplParams(i_s=[0.05, 2500.0, 1800.0], v_t=[0.2, 1000.0, 900.0],
                       w=[1.0, 0.5, 20.0, -20.0], v_b=0.1)
STRUCTURE = mpl.MplStructure(n_cells=3, dt=DT)



def _compensator(mode: str) -> Compensator:
    return Compensator(structure=STRUCTURE, params=PARAMS, mode=mode, center="fit",
                       scaling=Scaling(0.0, 1.0, 0.0, 1.0), baseline=LinearBaseline(1.0, 0.0),
                       model="mpl", training_range=(-1.5, 1.5), position_range=(-1.5, 1.5))


def _input(n: int = 3000) -> np.ndarray:
    t = np.arange(n) * DT
    return np.sin(0.5 * t) + 0.2 * np.random.default_rng(3).standard_normal(n)


def _kernel_args():
    return (PARAMS.i_s, PARAMS.v_t, PARAMS.w, PARAMS.v_b, mpl.knee_voltage(STRUCTURE, PARAMS),
            STRUCTURE.slope_cap / DT, DT)


def test_exported_forward_step_is_the_kernel_run_bit_for_bit(tmp_path):
    u = _input()
    knee = mpl.knee_voltage(STRUCTURE, PARAMS)
    assert np.isfinite(knee[0])  # the straight branch is exercised
    y, _ = kernels.simulate(u, np.full(3, u[0]), *_kernel_args())
    assert_array_equal(model_steps_in_c(tmp_path, _compensator("direct"), u), y)


def test_exported_inverse_step_is_the_kernel_inversion_bit_for_bit(tmp_path):
    y_in = _input()
    x0 = np.full(3, (y_in[0] + PARAMS.v_b) / float(np.sum(PARAMS.w)))
    u_hat, _, bad = kernels.invert(y_in, x0, *_kernel_args())
    assert bad == -1
    assert_array_equal(model_steps_in_c(tmp_path, _compensator("inverse"), y_in), u_hat)


def test_export_has_no_libm_sinh_per_sample():
    """The per-sample step calls no sinh (constants fixed at export, one exp per cell)."""
    source = c_files(make_plan(_compensator("direct"), name="cells"), double=True)["cells.c"]
    step = source[source.index("static real sinh_one_exp"):]
    assert "SINH(" not in step and "EXP(" in step
