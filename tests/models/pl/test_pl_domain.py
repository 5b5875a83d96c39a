"""The PL model's parameter domain (issue 10): every accepted parameter set runs finite and
within :func:`pl.output_bound`; sizes and parameters outside the domain are refused by name.

``HYSTKIT_FUZZ_EXAMPLES`` raises the number of hypothesis examples (a campaign run)."""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from hystkit.errors import FitDivergedError
from hystkit.models import pl
from hystkit.models.pl import FAMILY

from ..fuzz_strategies import values

EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "150"))
U = np.r_[0.9 * np.sin(np.linspace(0, 12, 240)), np.ones(30), -np.ones(30), 0.3 * np.ones(20)]


@st.composite
def models(draw):
    n, m = draw(st.integers(1, 3)), draw(st.integers(1, 4))
    structure = pl.PlStructure(n_cells=n, n_basis=m, power=draw(st.sampled_from([1.01, 5.0,
                                                                                  21.0, 1e3])),
                               dt=draw(st.sampled_from([1e-9, 0.025, 1e6])),
                               slope_cap=draw(st.floats(0.01, 1.99)))
    raw = {"i_t": values(draw, 1, pl.I_T_RANGE, signed=False)[0],
           "v_t": values(draw, 1, pl.V_T_RANGE, signed=False)[0],
           "w": values(draw, n + 1, (1e-3, 1e6)), "v_b": values(draw, 1, (1e-3, 1e6))[0],
           "a": values(draw, m, pl.A_RANGE, signed=False)}
    try:
        return structure, pl.PlParams(**raw)
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
    y, x = pl.simulate(structure, params, U)
    bound = pl.output_bound(structure, params, 1.0)  # + 1e-300 below: rounding of subnormal outputs
    assert np.all(np.isfinite(x)) and np.max(np.abs(y)) <= bound * (1 + 1e-9) + 1e-300
    block = FAMILY.block(structure, params)
    xb = np.full(structure.n_cells, U[0])
    for v in U[:40]:  # the compiled loop block agrees on finiteness and bound
        xn = np.empty_like(xb)
        assert abs(block.step(block.body, xb, xn, 0, v)) <= bound * (1 + 1e-9) + 1e-300
        xb = xn
    try:  # the inverse: finite or a clear FitDivergedError
        u_hat, x_end = pl.invert(structure, params, y)
    except FitDivergedError:
        return
    assert np.all(np.isfinite(u_hat)) and np.all(np.isfinite(x_end))


def test_the_reported_case_is_refused_by_name():
    """a = 1e-30 turned |u| <= 1 into |y| = 1e29 (issue 10)."""
    with pytest.raises(ValueError, match=r"a \(output resistor slopes\) must lie in "
                                         r"\[0.001, 1000\].*got 1e-30"):
        pl.PlParams(i_t=1.0, v_t=0.1, w=[1.0, 0.5], a=[1e-30])


@pytest.mark.parametrize("field, value", [("i_t", 0.0), ("i_t", 1e13), ("v_t", -0.1),
                                          ("v_t", np.nan), ("a", 0.0), ("a", 1e4),
                                          ("w", 2e6), ("v_b", -1e7)])
def test_out_of_domain_parameters_are_refused_by_name(field, value):
    raw = {"i_t": 1.0, "v_t": 0.1, "w": [1.0, 0.5], "v_b": 0.0, "a": [1.0]}
    raw[field] = [value] * len(raw[field]) if isinstance(raw[field], list) else value
    with pytest.raises(ValueError, match=field):
        pl.PlParams(**raw)


@pytest.mark.parametrize("field, value, message", [
    ("n_cells", 1001, "n_cells must be a whole number in"),
    ("n_cells", 20_000_000, "n_cells must be a whole number in"),
    ("n_basis", 10**9, "n_basis must be a whole number in"),
    ("n_basis", "abc", "n_basis must be a whole number in"),
    ("power", 1.0, "power p must lie in"), ("power", 1e9, "power p must lie in"),
    ("dt", 1e-12, "dt must lie in")])
def test_structure_limits_are_checked_first(field, value, message):
    with pytest.raises(ValueError, match=message):
        pl.PlStructure(**{field: value})


def test_params_with_too_many_cells_are_refused_before_copying():
    with pytest.raises(ValueError, match="1000"):
        pl.PlParams(i_t=1.0, v_t=0.1, w=np.ones(1002))


def test_the_fit_box_and_random_params_lie_inside_the_domain():
    structure = pl.PlStructure(n_cells=3, n_basis=50)
    rng = np.random.default_rng(0)
    for _ in range(50):
        pl.simulate(structure, FAMILY.random_params(structure, rng), U)
    for i_t in np.exp(pl.box.LOG_IT):
        for v_t in np.exp(pl.box.LOG_VT):
            pl.PlParams(i_t=i_t, v_t=v_t, w=[100.0, -100.0], v_b=-1e3,
                        a=[pl.box.A_MIN, 50 - pl.box.A_MIN * 49] + [pl.box.A_MIN] * 48)
