"""The mPL parameter domain (issue 10): every accepted parameter set runs finite and within
:func:`mpl.output_bound`; sizes and parameters outside the domain are refused by name.

``HYSTKIT_FUZZ_EXAMPLES`` raises the number of hypothesis examples (a campaign run)."""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from hystkit.errors import FitDivergedError
from hystkit.models import mpl
from hystkit.models.mpl import FAMILY

from ..fuzz_strategies import values

EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "150"))
U = np.r_[0.9 * np.sin(np.linspace(0, 12, 240)), np.ones(30), -np.ones(30), 0.3 * np.ones(20)]


@st.composite
def models(draw):
    n = draw(st.integers(1, 3))
    structure = mpl.MplStructure(n_cells=n, dt=draw(st.sampled_from([1e-9, 0.025, 1e6])),
                                 slope_cap=draw(st.floats(0.01, 1.99)))
    raw = {"i_s": values(draw, n, mpl.I_S_RANGE, signed=False),
           "v_t": values(draw, n, mpl.V_T_RANGE, signed=False),
           "w": values(draw, n + 1, (1e-3, 1e6)), "v_b": values(draw, 1, (1e-3, 1e6))[0]}
    try:
        return structure, mpl.MplParams(**raw)
    except ValueError as err:
        assert any(name in str(err) for name in raw), err  # names the parameter
        return structure, None


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(models())
def test_accepted_parameters_run_finite_and_bounded(model):
    structure, params = model
    event("refused" if params is None else "accepted")  # counts of a campaign run
    if params is None:
        return
    y, x = mpl.simulate(structure, params, U)
    bound = mpl.output_bound(structure, params, 1.0)  # + 1e-300 below: rounding of subnormal outputs
    assert np.all(np.isfinite(x)) and np.max(np.abs(y)) <= bound * (1 + 1e-12) + 1e-300
    out = FAMILY.block(structure, params)
    x_loop = np.full(structure.n_cells, U[0])
    for v in U[:40]:  # the compiled loop block agrees on finiteness and bound
        xn = np.empty_like(x_loop)
        assert abs(out.step(out.body, x_loop, xn, 0, v)) <= bound * (1 + 1e-12) + 1e-300
        x_loop = xn
    try:  # the inverse: finite or a clear FitDivergedError
        u_hat, x_end = mpl.invert(structure, params, y)
    except FitDivergedError:
        return
    assert np.all(np.isfinite(u_hat)) and np.all(np.isfinite(x_end))


@pytest.mark.parametrize("field, value", [("i_s", 0.0), ("i_s", -1.0), ("i_s", 1e13),
                                          ("v_t", 1e-7), ("v_t", np.nan), ("w", 2e6),
                                          ("v_b", -1e7), ("v_b", np.inf)])
def test_out_of_domain_parameters_are_refused_by_name(field, value):
    raw = {"i_s": [0.1], "v_t": [0.2], "w": [1.0, -0.5], "v_b": 0.0}
    raw[field] = value if field == "v_b" else [value] * len(raw[field])
    with pytest.raises(ValueError, match=field):
        mpl.MplParams(**raw)


@pytest.mark.parametrize("n", [0, 1001, 20_000_000, 2.5, "abc", np.inf])
def test_cell_count_is_limited_before_anything_is_allocated(n):
    with pytest.raises(ValueError, match=r"n_cells must be a whole number in \[1, 1000\]"):
        FAMILY.make_structure(0.025, n)
    with pytest.raises(ValueError, match="1000"):
        mpl.MplParams(i_s=np.ones(1001), v_t=np.ones(1001), w=np.ones(1002))


@pytest.mark.parametrize("dt", [1e-10, 1e7])
def test_sample_time_is_range_checked(dt):
    with pytest.raises(ValueError, match="dt must lie in"):
        FAMILY.make_structure(dt, 1)


@pytest.mark.parametrize("cap", [1e-300, 1e-7])
def test_slope_cap_has_a_floor(cap):
    with pytest.raises(ValueError, match=r"slope_cap must lie in \[1e-06, 2\]"):
        FAMILY.make_structure(0.025, 1, slope_cap=cap)


def test_the_fit_box_and_random_params_lie_inside_the_domain():
    """The domain holds everything the fit can return: its box corners at the extreme dts."""
    for dt in (1e-9, 0.025, 100.0):  # beyond ~1e4 s the fit box is empty (G floor 1e-4)
        structure = mpl.MplStructure(n_cells=2, dt=dt, slope_cap=1.99)
        for log_g in (mpl.box.LOG_G_MIN, np.log(structure.slope_cap / dt)):
            for log_vt in mpl.box.LOG_VT_BOUNDS:
                theta = np.r_[[log_g, log_vt] * 2, [100.0, -100.0, 100.0, -100.0]]
                mpl.MplParams.from_vector(theta, 2)  # raises if outside
        rng = np.random.default_rng(0)
        for _ in range(20):
            FAMILY.random_params(structure, rng)


def test_inputs_beyond_the_float_range_raise_instead_of_returning_inf():
    structure = mpl.MplStructure(n_cells=1)
    params = mpl.MplParams(i_s=[0.1], v_t=[0.2], w=[1e6, 1e6], v_b=0.0)
    with pytest.raises(FitDivergedError, match="mpl"):
        mpl.simulate(structure, params, np.array([1.7e308, -1.7e308]))
