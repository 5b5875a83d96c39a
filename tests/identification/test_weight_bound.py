"""``check_weights`` refuses weights above ``MAX_WEIGHT``, where ``w r^2`` and the weights'
sums would overflow (1e308: inf in numpy, illegal values in LAPACK)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from hystkit.identification import MAX_WEIGHT, check_weights


def test_weights_up_to_the_bound_pass_and_sum_finitely():
    w = np.full(10_000, MAX_WEIGHT)
    checked = check_weights(w, w.size)
    assert np.isfinite(checked.sum()) and np.isfinite(np.mean(checked * 4.0))


@pytest.mark.parametrize("value", [1e308, np.nextafter(MAX_WEIGHT, np.inf)])
def test_a_weight_above_the_bound_is_refused_naming_its_entry(value):
    w = np.ones(50)
    w[17] = value
    with pytest.raises(ValueError, match=re.escape(f"<= {MAX_WEIGHT:g}, entry 17 is")):
        check_weights(w, w.size)
