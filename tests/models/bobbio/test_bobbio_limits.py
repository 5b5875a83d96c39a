"""Bobbio-Marrucci limits (issue 10): the parameter domain keeps runs finite and within
``output_bound``, the spring count is capped before anything is allocated, short records are
refused; hypothesis fuzz over many decades, signs, zeros and subnormals."""

import os
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hystkit.models import bobbio, get_family

FAMILY = get_family("bobbio")
EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "200"))

_MAG = st.floats(-320, 300).map(lambda e: 10.0 ** e)
_NONNEG = st.one_of(st.just(0.0), st.just(5e-324), _MAG)
_SIGNED = st.one_of(_NONNEG, _NONNEG.map(lambda v: -v))


@pytest.mark.parametrize("n", [1e12, float("inf"), 1001, 0, 2.5, "abc"])
def test_spring_count_outside_the_cap_is_refused(n):
    with pytest.raises(ValueError, match="n_springs"):
        bobbio.BobbioStructure(n_springs=n)
    with pytest.raises(ValueError, match="n_springs"):
        FAMILY.make_structure(0.025, n)


def test_spring_count_at_the_cap_runs():
    s = FAMILY.make_structure(0.025, bobbio.MAX_SPRINGS)
    y, _ = FAMILY.simulate(s, FAMILY.random_params(s, np.random.default_rng(0)),
                           np.sin(np.arange(50) / 5))
    assert np.all(np.isfinite(y))


@pytest.mark.parametrize("field, value", [("compliance", 2e6), ("friction", 1e300),
                                          ("offset", -1e7)])
def test_values_beyond_the_domain_name_the_parameter(field, value):
    kwargs = {"compliance": np.ones(3), "friction": np.ones(2), "offset": 0.0}
    kwargs[field] = value if field == "offset" else np.full(np.size(kwargs[field]), value)
    message = f"{field} must be at most 1e+06 in magnitude (the domain where runs stay " \
              f"bounded), got {abs(value):g}"
    with pytest.raises(ValueError, match=re.escape(message)):
        bobbio.BobbioParams(**kwargs)


def test_short_records_are_refused():
    s = FAMILY.make_structure(0.025, 3)
    u = np.linspace(-1, 1, 6)
    with pytest.raises(ValueError, match="more samples than its 6 parameters, got 6"):
        FAMILY.fit(u, 0.5 * u, s)
    assert FAMILY.fit(np.linspace(-1, 1, 7), 0.5 * np.linspace(-1, 1, 7), s).cost < 1e-20


@settings(max_examples=EXAMPLES, deadline=None)
@given(n=st.integers(1, 6), data=st.data(), amp=_MAG, seed=st.integers(0, 2**32 - 1))
def test_fuzz_runs_are_finite_and_bounded_or_refused(check_bounded_run, n, data, amp, seed):
    compliance = data.draw(st.lists(_SIGNED, min_size=n, max_size=n))
    friction = data.draw(st.lists(_SIGNED, min_size=n - 1, max_size=n - 1))
    offset = data.draw(_SIGNED)
    try:
        p = bobbio.BobbioParams(compliance=compliance, friction=friction, offset=offset)
    except ValueError:
        values = np.abs([*compliance, *friction, offset])
        assert (min(compliance) < 0 or (friction and min(friction) <= 0)
                or values.max() > bobbio.MAX_VALUE)
        return
    s = FAMILY.make_structure(0.025, n)
    u = np.random.default_rng(seed).uniform(-1, 1, 100) * min(amp, 1e100)
    check_bounded_run(FAMILY, s, p, u, lambda m: bobbio.output_bound(p, m), rel=1e-12,
                      diverged=("sample",))
