"""Chua-Stromsmoe limits (issue 10): the parameter domain keeps runs finite and within
``output_bound`` at any slope cap, the element count is capped before anything is allocated,
short records are refused; hypothesis fuzz over many decades, zeros and subnormals."""

import os
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hystkit.models import chua, get_family

FAMILY = get_family("chua")
EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "150"))

_MAG = st.floats(-320, 300).map(lambda e: 10.0 ** e)
_NONNEG = st.one_of(st.just(0.0), st.just(5e-324), _MAG)
_SIGNED = st.one_of(_NONNEG, _NONNEG.map(lambda v: -v))
_FIELDS = ("k0", "k_inf", "y_s", "g", "v_g", "delta")


@pytest.mark.parametrize("n", [1e12, float("inf"), 101, 0, 2.5, "abc"])
def test_element_count_outside_the_cap_is_refused(n):
    with pytest.raises(ValueError, match="n_elements"):
        chua.ChuaStructure(n_elements=n)
    with pytest.raises(ValueError, match="n_elements"):
        FAMILY.make_structure(0.025, n)


def test_element_count_at_the_cap_runs():
    s = FAMILY.make_structure(0.025, chua.MAX_ELEMENTS)
    y, _ = FAMILY.simulate(s, FAMILY.random_params(s, np.random.default_rng(0)),
                           np.sin(np.arange(50) / 5))
    assert np.all(np.isfinite(y))


@pytest.mark.parametrize("field, value", [("k0", 1e-7), ("k_inf", 1e300), ("y_s", 5e-324),
                                          ("g", 1e13), ("v_g", 2e6), ("delta", 1e7)])
def test_values_beyond_the_domain_name_the_parameter(field, value):
    kwargs = dict.fromkeys(_FIELDS, np.ones(2))
    kwargs[field] = np.array([1.0, value])
    low, high = chua.DOMAIN[field]
    message = f"{field} must lie in [{low:g}, {high:g}] (the domain where runs stay bounded), " \
              f"got {value:g}"
    with pytest.raises(ValueError, match=re.escape(message)):
        chua.ChuaParams(**kwargs)


def test_short_records_are_refused():
    s = FAMILY.make_structure(0.025, 1)
    u = np.linspace(-1, 1, 6)
    with pytest.raises(ValueError, match="more samples than its 6 parameters, got 6"):
        FAMILY.fit(u, 0.5 * u, s)


def test_the_overshoot_bound_is_reached_not_just_respected():
    # slope cap 1.9 and an input alternating between +-1: each step overshoots by 0.9 of the
    # distance, so the element settles near s / (2 - s) = 19 times the equilibrium.
    s = FAMILY.make_structure(0.025, 1, slope_cap=1.9)
    p = chua.ChuaParams(k0=[1.0], k_inf=[1.0], y_s=[1.0], g=[1e12], v_g=[1e6], delta=[0.0])
    u = np.where(np.arange(400) % 2, 1.0, -1.0)
    y, _ = FAMILY.simulate(s, p, u, x0=0.0)
    bound = chua.output_bound(s, p, 1.0)
    assert bound == pytest.approx(19.0)
    assert 0.9 * bound < np.max(np.abs(y)) <= bound


@settings(max_examples=EXAMPLES, deadline=None)
@given(n=st.integers(1, 4), data=st.data(), amp=_MAG, cap=st.floats(1e-3, 1.99),
       seed=st.integers(0, 2**32 - 1))
def test_fuzz_runs_are_finite_and_bounded_or_refused(check_bounded_run, n, data, amp, cap, seed):
    values = {name: data.draw(st.lists(_SIGNED, min_size=n, max_size=n)) for name in _FIELDS}
    try:
        p = chua.ChuaParams(**values)
    except ValueError:
        assert any(not chua.DOMAIN[name][0] <= v <= chua.DOMAIN[name][1]
                   for name in _FIELDS for v in values[name])
        return
    s = FAMILY.make_structure(data.draw(st.sampled_from([1e-6, 0.025, 10.0])), n,
                              slope_cap=cap)
    u = np.random.default_rng(seed).uniform(-1, 1, 100) * min(amp, 1e100)
    check_bounded_run(FAMILY, s, p, u, lambda m: chua.output_bound(s, p, m), rel=1e-9,
                      diverged=("sample",))
