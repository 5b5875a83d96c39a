"""The polynomial mPL's parameter domain (issue 10): accepted parameters run finite, within
:func:`mpl_poly.output_bound` for ``slope_cap <= 1``, or raise FitDivergedError when the
limited resistors rest outside the domain at this ``dt``; the rest is refused by name.

``HYSTKIT_FUZZ_EXAMPLES`` raises the number of hypothesis examples (a campaign run)."""

import os
from functools import partial

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from hystkit.errors import FitDivergedError
from hystkit.models import mpl_poly as mp
from hystkit.models.mpl_poly import FAMILY

from ..fuzz_strategies import values as _values

EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "150"))
values = partial(_values, zeros=True)  # here a coefficient set to 0 is a case of its own
U = np.r_[0.9 * np.sin(np.linspace(0, 12, 240)), np.ones(30), -np.ones(30), 0.3 * np.ones(20)]


@st.composite
def models(draw):
    n = draw(st.integers(1, 2))
    structure = mp.MplPolyStructure(n_cells=n, dt=draw(st.sampled_from([1e-9, 0.025, 1e6])),
                                    slope_cap=draw(st.floats(1e-6, 1.99)))
    f = [values(draw, 3, (1e-4, 1e4)) + values(draw, 1, (1e-8, 1e4), signed=False)
         for _ in range(n)]
    raw = {"f": f, "g": values(draw, 4, (1e-4, 1e4)), "w": values(draw, n + 1, (1e-3, 1e6)),
           "v_b": values(draw, 1, (1e-3, 1e6))[0]}
    try:
        return structure, mp.MplPolyParams(**raw)
    except ValueError as err:
        assert any(name in str(err) for name in ("f", "g", "w", "v_b")), err
        return structure, None


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(models())
def test_accepted_parameters_run_finite_and_bounded(model):
    structure, params = model
    if params is None:
        event("refused")
        return
    try:
        y, x = mp.simulate(structure, params, U)
    except FitDivergedError as err:
        event("accepted, refused at this dt")
        assert "rests at" in str(err) or "left the finite range" in str(err), err
        with pytest.raises(FitDivergedError):  # the loop refuses it too
            FAMILY.block(structure, params)
        return
    event("accepted")
    assert np.all(np.isfinite(y)) and np.all(np.isfinite(x))
    if structure.slope_cap <= 1:
        assert np.max(np.abs(y)) <= mp.output_bound(structure, params, 1.0) * (1 + 1e-9) + 1e-300
    block = FAMILY.block(structure, params)
    xb = mp.rest_state(structure, params, U[0])
    for v in U[:30]:  # the compiled loop block stays finite too
        xn = np.empty_like(xb)
        assert np.isfinite(block.step(block.body, xb, xn, 0, v))
        xb = xn
    try:  # the inverse: finite or a clear FitDivergedError
        u_hat, x_end = mp.invert(structure, params, y)
    except FitDivergedError:
        return
    assert np.all(np.isfinite(u_hat)) and np.all(np.isfinite(x_end))


def test_the_reported_case_is_refused_with_its_rest_voltage():
    """Linear coefficient 0 and a cubic one far below the fit's floor: the cell would rest 1e10
    away from the data, outputs near 1e30 and more (issue 10); refused, naming the cell."""
    with pytest.raises(ValueError, match=r"f\[0\] \(cell 1's resistor\) has a rest voltage "
                                         r"at -1e\+10"):
        mp.MplPolyParams(f=[[0.0, 0.0, 1.0, 1e-10]], g=[0.0, 1.0, 0.0, 0.0], w=[1.0, -1.0])


def test_rest_points_moved_out_by_the_limit_are_refused_at_run_time():
    """Cubic roots 0, 0, -26000, but with slope_cap 0.0625 the straight continuation below the
    lower knee rests the cell at v = -1.04e12: runs and the loop refuse it."""
    s = mp.MplPolyStructure(n_cells=1, dt=0.025, slope_cap=0.0625)
    p = mp.MplPolyParams(f=[[0.0, 0.0, 26000.0, 1.0]], g=[0.0, 1.0, 0.0, 0.0], w=[1.0, -1.0])
    for run in (lambda: mp.simulate(s, p, U), lambda: mp.invert(s, p, U),
                lambda: FAMILY.block(s, p)):
        with pytest.raises(FitDivergedError, match=r"rests at v = -1.04\d*e\+12"):
            run()


@pytest.mark.parametrize("field, row, value, message", [
    ("f", 3, 0.0, "cubic coefficient"), ("f", 3, -1.0, "cubic coefficient"),
    ("f", 1, 2e9, "f"), ("f", 0, np.nan, "f"), ("g", 1, 1e10, "g"),
    ("g", 3, 5e-324, "g must be 0 or at least 1e-200"),
    ("w", 0, -2e6, "w"), ("v_b", None, 1e7, "v_b")])
def test_out_of_domain_parameters_are_refused_by_name(field, row, value, message):
    raw = {"f": [[0.0, 1.0, 0.0, 1.0]], "g": [0.0, 1.0, 0.0, 0.1], "w": [1.0, -0.5],
           "v_b": 0.0}
    if field == "f":
        raw["f"][0][row] = value
    elif row is None:
        raw[field] = value
    else:
        raw[field][row] = value
    with pytest.raises(ValueError, match=message):
        mp.MplPolyParams(**raw)


@pytest.mark.parametrize("n", [0, 1001, 20_000_000, "abc"])
def test_cell_count_is_limited_before_anything_is_allocated(n):
    with pytest.raises(ValueError, match=r"n_cells must be a whole number in \[1, 1000\]"):
        FAMILY.make_structure(0.025, n)


def test_params_with_too_many_cells_are_refused_before_copying():
    with pytest.raises(ValueError, match="1000"):
        mp.MplPolyParams(f=np.ones((1001, 4)), g=np.ones(4), w=np.ones(1002))


def test_presets_random_params_and_the_fit_box_corners_lie_inside_the_domain():
    for structure, params, _ in FAMILY.presets().values():
        mp.simulate(structure, params, U)  # neither refused nor diverged
    structure = mp.MplPolyStructure(n_cells=2)
    rng = np.random.default_rng(0)
    for _ in range(50):
        mp.simulate(structure, FAMILY.random_params(structure, rng), U)
