"""Hypothesis helpers shared by the families' domain tests (issue 10)."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st


def values(draw, n, domain, signed=True, zeros=False):
    """``n`` floats, each inside the domain ``domain = (lo, hi)`` of magnitudes (log-uniform,
    either sign if ``signed``) or, with a share drawn per example, anywhere: two decades past
    either end, negative, zero, subnormal, 1e300, 1.7e308. ``zeros``: a signed value is
    exactly 0 one time in ten (a linear or constant coefficient set to 0)."""
    lo, hi = np.log10(domain)
    share = draw(st.sampled_from([0.0, 0.1, 0.5]))
    out = []
    for _ in range(n):
        if draw(st.floats(0, 1)) < share:
            out.append(draw(st.one_of(
                st.sampled_from([0.0, -1.0, 5e-324, 1e-310, 1e300, 1.7e308, -1e300]),
                st.floats(lo - 2, hi + 2).map(lambda e: 10.0 ** e),
                st.floats(-320, 308).map(lambda e: -(10.0 ** e)))))
        elif zeros and signed and draw(st.integers(0, 9)) == 0:
            out.append(0.0)
        else:
            sign = draw(st.sampled_from([1.0, -1.0])) if signed else 1.0
            out.append(sign * 10.0 ** draw(st.floats(lo, hi)))
    return out
