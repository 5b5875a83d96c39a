"""The compiled block (``Family.block``): ``step(body, x, xn, off, u) -> out``.

Body: ``[rate, w0, w1, bias, dt]``; state: the lagged input ``x``.
"""

from numba import njit

RATE, W0, W1, BIAS, DT = range(5)  # the body's layout, shared with export.py


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    xn[off] = x[off] + body[RATE] * body[DT] * (u - x[off])
    return body[W0] * u + body[W1] * x[off] + body[BIAS]


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    u = (y - body[W1] * x[off] - body[BIAS]) / body[W0]
    xn[off] = x[off] + body[RATE] * body[DT] * (u - x[off])
    return u
