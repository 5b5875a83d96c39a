"""The readable ``invert_step`` of every family with an inverse, fuzzed directly (issue 10).

For random parameters from the family's documented domain (``random_params``) and bounded
outputs (the model's own response to a random input with |u| <= 1, plus a random wander of
the same size, which the model need not be able to produce), ``invert_step`` looped over the
samples from the inverse rest state must stay finite, give the outputs back when run forward
(the identity) and give ``family.invert``'s (compiled) estimate and end state; where the
compiled inverse raises ``FitDivergedError`` (its documented divergence error), the readable
loop may only return or raise that error. Hypothesis runs
derandomized (the same examples every run); the findings of random exploration are below.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hystkit.errors import FitDivergedError
from hystkit.models import FAMILIES, get_family

# Open findings (not yet analysed), strict expected failures (the examples are fixed): chua's readable and
# compiled inverses pick different inputs at some samples (seed 1782420, sample 109: -0.958 and
# 0.030) and its forward run from its own rest state does not give the outputs back from the
# readable inverse's input (seed 62625); gpreisach's readable invert_step refuses a state its
# inverse produced ("the state must alternate rising/falling ...", seed 0, size 2x); ladder's
# forward run does not give the outputs back from the readable inverse's input (seed 44384473,
# not among the derandomized examples, so ladder runs here).
_OPEN = {"chua": "readable and compiled inverses differ; identity fails on some draws",
         "gpreisach": "readable invert_step refuses a state the inverse produced"}
INVERTIBLE = [pytest.param(name, marks=pytest.mark.xfail(reason=_OPEN[name], strict=True))
              if name in _OPEN else name
              for name in sorted(n for n in FAMILIES if get_family(n).has_inverse)]
N = 120  # samples per example: several reversals, quick in pure Python


def _outputs(family, structure, params, rng: np.random.Generator, wander: bool) -> np.ndarray:
    u = np.clip(np.cumsum(rng.normal(0.0, 0.15, N)), -1.0, 1.0)
    y, _ = family.simulate(structure, params, u)
    if wander:  # the same range, but a path the forward model may never take
        y = np.max(np.abs(y)) * np.clip(np.cumsum(rng.normal(0.0, 0.2, N)), -1.0, 1.0)
    return y


def _readable(family, structure, params, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x = family.rest_state(structure, params, float(y[0]), True)
    u_hat = np.empty(y.size)
    for k, y_k in enumerate(y):
        u_hat[k], x = family.invert_step(structure, params, x, y_k)
    return u_hat, np.asarray(x, dtype=float)


@pytest.mark.parametrize("name", INVERTIBLE)
@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), factor=st.sampled_from([1, 2]), wander=st.booleans())
def test_readable_inverse_equals_compiled(name: str, seed: int, factor: int,
                                          wander: bool) -> None:
    family = get_family(name)
    structure = family.make_structure(0.025, factor * family.default_size)
    rng = np.random.default_rng(seed)
    params = family.random_params(structure, rng)
    y = _outputs(family, structure, params, rng, wander)
    try:
        u_fast, x_fast = family.invert(structure, params, y)
    except FitDivergedError:
        # The compiled inverse left its documented range. The readable loop, whose rounding
        # differs, may cross that threshold earlier, later or not at all within N samples (an
        # unstable inverse), but it must not fail in any other way.
        with np.errstate(all="ignore"):
            try:
                _readable(family, structure, params, y)
            except FitDivergedError:
                pass
        return
    u_slow, x_slow = _readable(family, structure, params, y)
    assert np.all(np.isfinite(u_slow)) and np.all(np.isfinite(x_slow))
    if not wander:
        # the identity, independent of the compiled code: the model driven by the readable
        # inverse's input gives its own outputs back (to rounding of the outputs' size)
        y_back, _ = family.simulate(structure, params, u_slow)
        np.testing.assert_allclose(y_back, y, rtol=0, atol=1e-9 * (1.0 + np.max(np.abs(y))))
    # Agreement: another order of the same arithmetic differs by rounding, grown by the
    # inverse's own amplification (the inverse of a domain draw may be unstable, even chaotic,
    # and two exact implementations then part ways). Measured on the compiled inverse: its
    # response to random relative changes of 1e-12 of every output. The samples before that
    # response passes 1e-6 (amplification still linear) must agree within the response
    # scaled to 1e-13 (~450 ulps: the readable steps solve their implicit equations by other
    # iterations; mpl seed 138703609 needs ~1e-13); after, the identity above is the check.
    kick = y * (1.0 + 1e-12 * rng.standard_normal(y.size))
    try:
        kicked, x_kicked = family.invert(structure, params, kick)
    except FitDivergedError:
        return
    response = np.abs(kicked - u_fast)
    n_linear = int(np.argmax(response > 1e-6)) if np.any(response > 1e-6) else y.size
    scale = 1.0 + np.max(np.abs(u_fast))
    assert np.all(np.abs(u_slow - u_fast)[:n_linear]
                  <= (1e-9 * scale + 0.1 * response)[:n_linear])
    if n_linear == y.size:
        x_fast = np.asarray(x_fast, float)
        x_response = np.abs(np.asarray(x_kicked, float) - x_fast)
        assert np.all(np.abs(x_slow - x_fast)
                      <= 1e-9 * (1.0 + np.max(np.abs(x_fast))) + 0.1 * x_response)
