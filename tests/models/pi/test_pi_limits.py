"""Modified PI limits (issue 10): the parameter domain keeps runs finite and within
``output_bound``, operator counts are capped before anything is allocated, short records are
refused; hypothesis fuzz over many decades, signs, zeros and subnormals."""

import os
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hystkit.models import get_family, pi

FAMILY = get_family("pi")
EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "200"))

_MAG = st.floats(-320, 300).map(lambda e: 10.0 ** e)
_NONNEG = st.one_of(st.just(0.0), st.just(5e-324), _MAG)
_SIGNED = st.one_of(_NONNEG, _NONNEG.map(lambda v: -v))


@pytest.mark.parametrize("size", [1e12, float("inf"), float("nan"), 1001, 0, 2.5, "abc"])
def test_play_count_outside_the_cap_is_refused(size):
    with pytest.raises(ValueError, match=r"size \(play operators\) must be an integer"):
        FAMILY.make_structure(0.025, size)


@pytest.mark.parametrize("kwargs, name", [
    ({"play_thresholds": tuple(range(1001))}, "play_thresholds"),
    ({"creep_rates": (1.0,) * 21}, "creep_rates"),
    ({"n_deadzone": 1e12}, "n_deadzone"), ({"n_deadzone": float("inf")}, "n_deadzone"),
    ({"n_deadzone": "abc"}, "n_deadzone"), ({"play_thresholds": (0.0, 2e6)}, "play_thresholds")])
def test_structures_beyond_the_caps_name_the_field(kwargs, name):
    with pytest.raises(ValueError, match=name):
        pi.PiStructure(**kwargs)
    with pytest.raises(ValueError, match=name):
        pi.PiStructure.from_dict({**pi.PiStructure().to_dict(), **kwargs})


def test_creep_count_outside_the_cap_is_refused():
    with pytest.raises(ValueError, match=r"n_creep must be an integer in \[0, 20\]"):
        FAMILY.make_structure(0.025, 5, n_creep=1e12)


def test_sizes_at_the_caps_run():
    s = FAMILY.make_structure(0.025, pi.MAX_PLAYS, n_creep=pi.MAX_CREEP,
                              n_deadzone=pi.MAX_DEADZONES)
    with np.errstate(over="ignore"):  # 10^19 s creep time constants: gain 0 is fine
        p = FAMILY.random_params(s, np.random.default_rng(0))
    y, _ = FAMILY.simulate(s, p, np.sin(np.arange(50) / 5))
    assert np.all(np.isfinite(y))


@pytest.mark.parametrize("field, value", [("w_h", 2e6), ("w_s", -1e300), ("w_k", 1e7),
                                          ("b", -5e6)])
def test_values_beyond_the_domain_name_the_parameter(field, value):
    kwargs = {"w_h": np.ones(2), "w_s": np.ones(3), "d_s": [-1.0, 0.0, 1.0], "w_k": np.ones(2),
              "b": 0.0}
    kwargs[field] = value if field == "b" else np.full(np.size(kwargs[field]), value)
    message = f"{field} must be at most 1e+06 in magnitude (the domain where runs stay " \
              f"bounded), got {abs(value):g}"
    with pytest.raises(ValueError, match=re.escape(message)):
        pi.PiParams(**kwargs)


def test_short_records_are_refused():
    s = FAMILY.make_structure(0.025, 3, n_creep=1, n_deadzone=1)
    u = np.linspace(-1, 1, 8)
    with pytest.raises(ValueError, match="more samples than its 8 unknowns, got 8"):
        FAMILY.fit(u, 0.5 * u, s)


@settings(max_examples=EXAMPLES, deadline=None)
@given(n=st.integers(1, 5), m=st.integers(0, 2), n_k=st.integers(0, 3), data=st.data(),
       amp=_MAG, seed=st.integers(0, 2**32 - 1))
def test_fuzz_runs_are_finite_and_bounded_or_refused(check_bounded_run, n, m, n_k, data, amp, seed):
    draw = data.draw
    w_h, w_s, w_k = (draw(st.lists(_SIGNED, min_size=k, max_size=k)) for k in (n, 2 * m + 1, n_k))
    gaps = [draw(_MAG) for _ in range(2 * m)]
    with np.errstate(over="ignore"):
        d_s = np.concatenate([-np.cumsum(gaps[:m])[::-1], [0.0], np.cumsum(gaps[m:])])
    b = draw(_SIGNED)
    try:
        p = pi.PiParams(w_h=w_h, w_s=w_s, d_s=d_s, w_k=w_k, b=b)
    except ValueError:
        values = np.abs(np.concatenate([w_h, w_s, d_s, w_k, [b]]))
        assert not np.all(values <= pi.MAX_VALUE) or np.any(np.diff(d_s) <= 0)
        return
    s = FAMILY.make_structure(draw(st.sampled_from([1e-6, 0.025, 10.0])), n, n_creep=n_k,
                              n_deadzone=m)
    u = np.random.default_rng(seed).uniform(-1, 1, 100) * min(amp, 1e100)
    check_bounded_run(FAMILY, s, p, u, lambda m: pi.output_bound(p, m), rel=1e-9,
                      diverged=("inverse", "static gain"))
