"""The readable ``invert_step`` of every family with an inverse, fuzzed directly (issue 10).

For random parameters from the family's documented domain (``random_params``) and bounded
outputs (the model's own response to a random input with |u| <= 1, plus a random wander of
the same size, which the model need not be able to produce), ``invert_step`` looped over the
samples from the inverse rest state must give ``family.invert``'s (compiled) estimate and end
state, and stay finite; where the compiled inverse raises ``FitDivergedError`` (its documented
divergence error), the readable loop must not return a finite, bounded result either.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hystkit.errors import FitDivergedError
from hystkit.models import FAMILIES, get_family

# Findings of this test, open (issue 10): chua's readable and compiled inverses pick different
# inputs for outputs the model cannot produce (up to 0.7 apart: a non-unique inverse, resolved
# differently) and still mismatch on some producible ones (seed 1782420, not yet analysed);
# gpreisach mismatches on some draws (seed 0, size 2x, not yet analysed); mpl-poly's inverse
# drifts on some domain draws (|u_hat| up to 4.6 from |u| <= 1) and its two implementations
# drift apart (0.025), and the readable one needed brentq's iteration cap raised. Until
# analysed and fixed they run here as non-strict expected failures.
_OPEN = {"mpl-poly": "readable and compiled inverses drift apart on some domain draws",
         "chua": "readable and compiled inverses mismatch on some draws (not yet analysed)",
         "gpreisach": "readable and compiled inverses mismatch on some draws (not yet analysed)"}
_PRODUCIBLE_ONLY = {"chua"}  # outputs off the model's range: the inverse is not unique
INVERTIBLE = [pytest.param(name, marks=pytest.mark.xfail(reason=_OPEN[name], strict=False))
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
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), factor=st.sampled_from([1, 2]), wander=st.booleans())
def test_readable_inverse_equals_compiled(name: str, seed: int, factor: int,
                                          wander: bool) -> None:
    family = get_family(name)
    wander = wander and name not in _PRODUCIBLE_ONLY
    structure = family.make_structure(0.025, factor * family.default_size)
    rng = np.random.default_rng(seed)
    params = family.random_params(structure, rng)
    y = _outputs(family, structure, params, rng, wander)
    try:
        u_fast, x_fast = family.invert(structure, params, y)
    except FitDivergedError:
        with np.errstate(all="ignore"):
            try:
                u_slow, _ = _readable(family, structure, params, y)
            except (FitDivergedError, FloatingPointError, OverflowError):
                return
        assert not np.all(np.isfinite(u_slow)) or np.max(np.abs(u_slow)) > 1e6
        return
    u_slow, x_slow = _readable(family, structure, params, y)
    assert np.all(np.isfinite(u_slow)) and np.all(np.isfinite(x_slow))
    # Another root finder and another order of the same arithmetic: they agree to rounding,
    # grown by the inverse's own sensitivity (a flat output map amplifies y's last bits). The
    # compiled inverse's response to a 1e-10 relative change of y, scaled to 1e-14 (~50 ulps).
    try:
        nudged, _ = family.invert(structure, params, y * (1 + 1e-10))
        sensitivity = 1e-4 * np.abs(nudged - u_fast)
    except FitDivergedError:
        sensitivity = 0.0
    scale = 1.0 + np.max(np.abs(u_fast))
    assert np.all(np.abs(u_slow - u_fast) <= 1e-9 * scale + sensitivity)
    np.testing.assert_allclose(x_slow, np.asarray(x_fast, float), rtol=1e-9,
                               atol=1e-9 * (1.0 + np.max(np.abs(x_fast))))
