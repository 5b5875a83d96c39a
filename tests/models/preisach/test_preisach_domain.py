"""The classical Preisach model's domain and limits (issue 10): accepted Everett tables run
finite and within :func:`output_bound`, the inverse is finite and bounded or refused; levels
and capacity are capped before any table or staircase is allocated.

``HYSTKIT_FUZZ_EXAMPLES`` raises the number of hypothesis examples (a campaign run)."""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from hystkit.errors import FitDivergedError
from hystkit.models import preisach as P
from hystkit.models.preisach import FAMILY

EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "150"))
U = np.r_[0.9 * np.sin(np.linspace(0, 12, 240)), np.ones(30), -np.ones(30), 0.3 * np.ones(20),
          1.5 * np.sin(np.linspace(0, 6, 60))]  # beyond saturation too


@st.composite
def models(draw):
    """A table of masses of one decade each (log-uniform over 1e-12 .. 1e8, either sign), and
    sometimes one entry anywhere in the float range (zero, subnormal, 1e300, NaN)."""
    levels = draw(st.integers(2, 12))
    n_cells = (levels - 1) * (levels - 1)
    scale = 10.0 ** draw(st.floats(-12, 8))
    masses = np.asarray(draw(st.lists(st.floats(-1, 1), min_size=n_cells, max_size=n_cells)))
    masses = np.tril(scale * masses.reshape(levels - 1, levels - 1))
    offset = draw(st.sampled_from([0.0, 0.3, -2e6, 1e300]))
    try:
        everett = P.everett_from_masses(masses)
        if draw(st.booleans()):
            i = draw(st.integers(1, levels - 1))
            everett[i, draw(st.integers(0, i - 1))] = draw(st.sampled_from(
                [5e-324, -1e300, 1.7e308, np.nan, np.inf]))
        return levels, P.PreisachParams(everett, offset=offset)
    except ValueError as err:
        assert "everett" in str(err) or "offset" in str(err), err
        return levels, None


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(models())
def test_accepted_tables_run_finite_and_bounded(model):
    levels, params = model
    event("refused" if params is None else "accepted")  # counts of a campaign run
    if params is None:
        return
    structure = P.PreisachStructure(levels=levels)
    y, _ = P.simulate(structure, params, U)
    assert np.all(np.abs(y) <= P.output_bound(params, 1.5) * (1 + 1e-9) + 1e-300)
    try:
        u_hat, _ = P.invert(structure, params, y)
    except FitDivergedError as err:
        assert "no inverse" in str(err)
        return
    rise, mass = params.everett[-1, 0], np.abs(params.masses()).sum()
    assert np.all(np.abs(u_hat) <= 1 + (np.max(np.abs(y - params.offset)) + mass) / rise)


@pytest.mark.parametrize("levels", [129, 512, 10**9, 2.5, "abc", 1])
def test_levels_are_limited_before_any_table_is_allocated(levels):
    with pytest.raises(ValueError, match="levels must be"):
        FAMILY.make_structure(0.025, levels)


def test_capacity_is_limited():
    with pytest.raises(ValueError, match=r"capacity must be a whole number in \[1, 1048576\]"):
        P.PreisachStructure(levels=8, capacity=10**12)


def test_a_model_file_with_a_huge_table_is_refused_before_it_is_built():
    rows = [[0.0] * 1] * 100_000  # 1e5 rows would make a 1e10-entry table
    with pytest.raises(ValueError, match="levels"):
        P.PreisachParams.from_dict({"everett": rows, "offset": 0.0})


@pytest.mark.parametrize("value", [2e6, -1e300, np.nan])
def test_everett_values_outside_the_domain_are_refused_by_name(value):
    e = np.zeros((4, 4))
    e[3, 0] = value
    with pytest.raises(ValueError, match="everett"):
        P.PreisachParams(e)


def test_a_barely_rising_loop_has_no_inverse():
    """A rise of 1e-12 against a mass of 1 would turn output noise into inputs near 1e12."""
    masses = np.zeros((3, 3))
    masses[2, 0], masses[1, 1] = 1.0, -1.0 + 1e-12
    params = P.PreisachParams.from_masses(masses)
    for run in (lambda: P.invert(P.PreisachStructure(levels=4), params, np.zeros(3)),
                lambda: FAMILY.block(P.PreisachStructure(levels=4), params, inverse=True)):
        with pytest.raises(FitDivergedError, match="no inverse"):
            run()
