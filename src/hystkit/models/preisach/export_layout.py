"""The layout of the staircase block's body as the C and MATLAB translations read it
(``[capacity, L, K, weighted, slope, tol, n_poly, poly (n_poly), A (K L L)]``, see
:mod:`.export`) and the inverse's tolerances.
"""

from __future__ import annotations

__all__ = ["FLOAT_TOL", "REST_TOL", "body_sizes"]

REST_TOL = 1e-12  # kernels.REST_TOL
# In float the inverse's tolerances (the rest test and the bisection's bracket, 1e-12 for
# double) are ~16 float epsilons: below that the bisection only collects rounding noise.
FLOAT_TOL = 2e-6


def body_sizes(plan) -> tuple[int, int, int, int]:
    """``(capacity, L, K, n_poly)`` read from the body of the export plan's block."""
    cap, levels, n_tab, n_poly = (int(plan.body[i]) for i in (0, 1, 2, 6))
    return cap, levels, n_tab, n_poly
