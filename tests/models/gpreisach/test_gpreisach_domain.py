"""The generalised Preisach model's domain (issue 10): accepted weights run finite and within
:func:`gpreisach.output_bound`, the inverse is finite or refused; sizes are the classical
model's (levels capped before any table is built).

``HYSTKIT_FUZZ_EXAMPLES`` raises the number of hypothesis examples (a campaign run)."""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from hystkit.errors import FitDivergedError
from hystkit.models import gpreisach as G
from hystkit.models import preisach as P
from hystkit.models.gpreisach import FAMILY

EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "150"))
U = np.r_[0.9 * np.sin(np.linspace(0, 12, 240)), np.ones(30), -np.ones(30), 0.3 * np.ones(20),
          1.5 * np.sin(np.linspace(0, 6, 60))]  # beyond saturation too
WILD = [5e-324, -1e300, 1.7e308, np.nan, -2e6]


def table(draw, levels):
    """Everett table of masses of one decade (log-uniform 1e-12 .. 1e8, either sign)."""
    n = (levels - 1) * (levels - 1)
    masses = np.asarray(draw(st.lists(st.floats(-1, 1), min_size=n, max_size=n)))
    return P.everett_from_masses(np.tril(10.0 ** draw(st.floats(-12, 8))
                                         * masses.reshape(levels - 1, levels - 1)))


@st.composite
def models(draw):
    """Random weights, and sometimes one value anywhere in the float range."""
    levels, degree = draw(st.integers(2, 10)), draw(st.integers(0, 8))
    raw = {"everett_minus": table(draw, levels), "everett_plus": table(draw, levels),
           "nu": 10.0 ** draw(st.floats(-12, 8)) * np.asarray(
               draw(st.lists(st.floats(-1, 1), min_size=degree + 1, max_size=degree + 1))),
           "offset": draw(st.floats(-1, 1))}
    where = draw(st.sampled_from([None, None, "nu", "everett_plus", "offset"]))
    if where == "offset":
        raw["offset"] = draw(st.sampled_from(WILD))
    elif where is not None:
        raw[where].reshape(-1)[-1 if where == "nu" else levels * (levels - 1)] = \
            draw(st.sampled_from(WILD))
    try:
        return G.GPreisachStructure(levels=levels, degree=degree), G.GPreisachParams(**raw)
    except ValueError as err:
        assert any(name in str(err) for name in ("everett", "nu", "offset")), err
        return None, None


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(models())
def test_accepted_weights_run_finite_and_bounded(model):
    structure, params = model
    event("refused" if params is None else "accepted")  # counts of a campaign run
    if params is None:
        return
    y, _ = G.simulate(structure, params, U)
    assert np.all(np.abs(y) <= G.output_bound(params, 1.5) * (1 + 1e-9) + 1e-300)
    try:
        u_hat, _ = G.invert(structure, params, y)
    except FitDivergedError as err:
        assert "no inverse" in str(err)
        return
    assert np.all(np.isfinite(u_hat))


@pytest.mark.parametrize("levels", [129, 512, 10**9, "abc"])
def test_levels_are_limited_before_any_table_is_allocated(levels):
    with pytest.raises(ValueError, match="levels must be"):
        FAMILY.make_structure(0.025, levels)


@pytest.mark.parametrize("field, value", [("nu", 2e6), ("nu", np.nan), ("offset", -1e7),
                                          ("everett_plus", 1e300)])
def test_values_outside_the_domain_are_refused_by_name(field, value):
    raw = {"everett_minus": np.zeros((4, 4)), "everett_plus": np.zeros((4, 4)),
           "nu": [1.0, 1.0], "offset": 0.0}
    if field == "everett_plus":
        raw[field][3, 0] = value
    elif field == "nu":
        raw[field] = [value, 1.0]
    else:
        raw[field] = value
    with pytest.raises(ValueError, match=field.split("_")[0]):
        G.GPreisachParams(**raw)


def test_random_params_lie_inside_the_domain():
    structure = G.GPreisachStructure(levels=12)
    rng = np.random.default_rng(0)
    for _ in range(30):
        G.simulate(structure, FAMILY.random_params(structure, rng), U)
