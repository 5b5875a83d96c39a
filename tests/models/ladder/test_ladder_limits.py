"""Ladder limits (issue 10): the parameter domain and ``slope_cap <= 1`` keep runs finite and
within ``output_bound``, the section count is capped before anything is allocated, short
records are refused; hypothesis fuzz over many decades, signs, zeros and subnormals."""

import os
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hystkit.models import get_family, ladder

FAMILY = get_family("ladder")
EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "200"))

_MAG = st.floats(-320, 300).map(lambda e: 10.0 ** e)
_NONNEG = st.one_of(st.just(0.0), st.just(5e-324), _MAG)
_SIGNED = st.one_of(_NONNEG, _NONNEG.map(lambda v: -v))


@pytest.mark.parametrize("n", [1e12, float("inf"), 1001, 0, 2.5, "abc"])
def test_section_count_outside_the_cap_is_refused(n):
    with pytest.raises(ValueError, match="n_cells"):
        ladder.LadderStructure(n_cells=n)
    with pytest.raises(ValueError, match="n_cells"):
        FAMILY.make_structure(0.025, n)


def test_section_count_at_the_cap_runs():
    s = FAMILY.make_structure(0.025, ladder.MAX_CELLS)
    y, _ = FAMILY.simulate(s, FAMILY.random_params(s, np.random.default_rng(0)),
                           np.sin(np.arange(50) / 5))
    assert np.all(np.isfinite(y))


@pytest.mark.parametrize("cap", [1.0 + 1e-9, 1.3, 1.9])
def test_slope_caps_beyond_one_are_refused(cap):
    with pytest.raises(ValueError, match=r"slope_cap must lie in \(0, 1\] for the ladder"):
        FAMILY.make_structure(0.025, 5, slope_cap=cap)


@pytest.mark.parametrize("n", [1, 2, 5, 50])
def test_fastest_conductances_at_the_cap_stay_within_the_input_range(n):
    # the case that diverged with slope_cap 1.3 - 1.9 (NaN from 5 sections on)
    s = FAMILY.make_structure(0.025, n, slope_cap=1.0)
    p = ladder.LadderParams(band=np.zeros(n), conductance=np.full(n, 1e300), w=np.ones(n + 1))
    u = np.sin(np.arange(2000) / 10.0)
    states, _ = ladder.states(s, p, u)
    assert np.all(np.abs(states) <= 1.0)


@pytest.mark.parametrize("field, value", [("band", 2e6), ("w", -1e300), ("v_b", 1e7)])
def test_values_beyond_the_domain_name_the_parameter(field, value):
    kwargs = {"band": np.ones(2), "conductance": np.ones(2), "w": np.ones(3), "v_b": 0.0}
    kwargs[field] = value if field == "v_b" else np.full(np.size(kwargs[field]), value)
    message = f"{field} must be at most 1e+06 in magnitude (the domain where runs stay " \
              f"bounded), got {abs(value):g}"
    with pytest.raises(ValueError, match=re.escape(message)):
        ladder.LadderParams(**kwargs)


def test_short_records_are_refused():
    s = FAMILY.make_structure(0.025, 2)
    u = np.linspace(-1, 1, 8)
    with pytest.raises(ValueError, match="more samples than its 8 parameters, got 8"):
        FAMILY.fit(u, 0.5 * u, s)


@settings(max_examples=EXAMPLES, deadline=None)
@given(n=st.integers(1, 6), data=st.data(), amp=_MAG, cap=st.floats(1e-3, 1.0),
       seed=st.integers(0, 2**32 - 1))
def test_fuzz_runs_are_finite_and_bounded_or_refused(check_bounded_run, n, data, amp, cap, seed):
    band = data.draw(st.lists(_SIGNED, min_size=n, max_size=n))
    conductance = data.draw(st.lists(_SIGNED, min_size=n, max_size=n))
    w = data.draw(st.lists(_SIGNED, min_size=n + 1, max_size=n + 1))
    v_b = data.draw(_SIGNED)
    try:
        p = ladder.LadderParams(band=band, conductance=conductance, w=w, v_b=v_b)
    except ValueError:
        assert (min(band) < 0 or min(conductance) <= 0
                or np.abs([*band, *w, v_b]).max() > ladder.MAX_VALUE)
        return
    s = FAMILY.make_structure(data.draw(st.sampled_from([1e-6, 0.025, 10.0])), n,
                              slope_cap=cap)
    u = np.random.default_rng(seed).uniform(-1, 1, 100) * min(amp, 1e100)
    check_bounded_run(FAMILY, s, p, u, lambda m: ladder.output_bound(p, m), rel=1e-12,
                      diverged=("sample", "w_0 = 0"))
