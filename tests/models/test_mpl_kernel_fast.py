"""mPL kernels with one exp per cell (issue 29, item 2): the readable reference's results, and
the runs, the blocks and the fit's pass advancing the state bit for bit alike."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.models import get_family, mpl
from hystkit.models.mpl import kernels

DT = 0.025
# Cell 1 crosses its knee (1.0) on the noise; cells 2 and 3 are nearly linear (V_T ~ 1e3, as a
# 5-cell fit of the virtual sensor gives), where (e - 1/e) / 2 cancels, and their large
# opposite weights keep y of order 1 while adding up their states' errors.
NEAR_LINEAR = mpl.MplParams(i_s=[0.05, 2500.0, 1800.0], v_t=[0.2, 1000.0, 900.0],
                            w=[1.0, 0.5, 20.0, -20.0], v_b=0.1)
STRUCTURE = mpl.MplStructure(n_cells=3, dt=DT)


def _input(n: int = 4000, seed: int = 3, noise: float = 0.2) -> np.ndarray:
    t = np.arange(n) * DT
    return np.sin(0.5 * t) + noise * np.random.default_rng(seed).standard_normal(n)


def _unguarded_run(structure, params, u):
    """The run with sinh(a) = (e - 1/e) / 2 at every |a|, the straight branch as the reference."""
    knee = mpl.knee_voltage(structure, params)
    x, y = np.full(structure.n_cells, u[0]), np.empty(u.size)
    for n, u_n in enumerate(u):
        y[n] = params.w[0] * u_n + params.w[1:] @ x - params.v_b
        v = u_n - x
        e = np.exp(v / params.v_t)
        inside = params.i_s * (e - 1 / e)
        x = x + np.where(np.abs(v) <= knee, inside,
                         mpl.resistor_current(structure, params, v)) * structure.dt
    return y


def test_one_exp_run_is_the_readable_reference_where_the_plain_form_is_not():
    """Both directions: the kernel is within 1e-13 of the readable steps (measured 3.9e-15);
    sinh = (e - 1/e) / 2 without the series below |a| = 0.5 is not (measured 6.3e-13)."""
    u = _input()
    ref, _ = mpl.simulate_reference(STRUCTURE, NEAR_LINEAR, u)
    y, _ = mpl.simulate(STRUCTURE, NEAR_LINEAR, u)
    scale = np.max(np.abs(ref))
    assert np.max(np.abs(y - ref)) / scale < 1e-13
    assert np.max(np.abs(_unguarded_run(STRUCTURE, NEAR_LINEAR, u) - ref)) / scale > 1e-13


def _kernel_args(structure, params, u):
    return (np.full(structure.n_cells, u[0]), params.i_s, params.v_t, params.w, params.v_b,
            mpl.knee_voltage(structure, params), structure.slope_cap / structure.dt,
            structure.dt)


@pytest.mark.parametrize("limit", [True, False])
def test_jacobian_run_and_one_pass_follow_simulate_bit_for_bit(limit):
    structure = mpl.MplStructure(n_cells=3, dt=DT, limit=limit)
    u = _input(3000)
    args = _kernel_args(structure, NEAR_LINEAR, u)
    y, _ = kernels.simulate(u, *args)
    y_jac, _ = kernels.simulate_with_jacobian(u, *args)
    assert_array_equal(y_jac, y)
    target = np.tanh(u)
    sse, _, _ = kernels.normal_equations(u, target, *args)
    assert sse == np.cumsum((y - target) ** 2)[-1]  # the sequential sum of simulate's residuals


# Inverse-stable weights (the inverse's cells see -(1 + w_k / w_0) of their own voltage).
TWO_CELLS = mpl.MplParams(i_s=[0.1, 0.02], v_t=[0.2, 0.5], w=[1.0, 0.4, -0.3], v_b=-0.6)


@pytest.mark.parametrize(("params", "inverse"), [(NEAR_LINEAR, False), (TWO_CELLS, False),
                                                 (TWO_CELLS, True)])
def test_block_steps_are_the_run_bit_for_bit(params, inverse):
    """The stream and the control loop step the block; it must give the run's bits, on a
    signal whose jumps take cell 1 past its knee."""
    structure = mpl.MplStructure(n_cells=params.n_cells, dt=DT)
    u = _input(2000, seed=5, noise=1.0)
    assert _knee_crossings(structure, params, u) > 20
    family = get_family("mpl")
    block = family.block(structure, params, inverse)
    if inverse:
        drive, _ = mpl.simulate(structure, params, u)
        want, want_end = mpl.invert(structure, params, drive)
    else:
        drive = u
        want, want_end = mpl.simulate(structure, params, u)
    x = family.rest_state(structure, params, float(drive[0]), inverse)
    a, b = np.array(x, dtype=float), np.empty(block.n_state)
    got = np.empty(drive.size)
    for k, value in enumerate(drive):
        b[:] = a
        got[k] = block.step(block.body, a, b, 0, value)
        a, b = b, a
    assert_array_equal(got, want)
    assert_array_equal(a, want_end)


def _knee_crossings(structure, params, u) -> int:
    """Samples at which cell 1 of the forward run is on its straight branch (its state read
    as the output of the same cells weighted [0, 1, 0, ...])."""
    w = np.zeros(params.n_cells + 1)
    w[1] = 1.0
    only_cell_1 = mpl.MplParams(i_s=params.i_s, v_t=params.v_t, w=w)
    x1, _ = mpl.simulate(structure, only_cell_1, u)
    return int(np.count_nonzero(np.abs(u - x1) > mpl.knee_voltage(structure, params)[0]))
