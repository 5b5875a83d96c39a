"""Compiled hot loops of the Preisach models; ``model.py`` holds the readable reference.

Shared by the classical (this folder) and the generalised (``models/gpreisach``) model. The
memory is the staircase of dominant extrema ``s[0] = -1, s[1], ..., s[n-1]`` (the last entry is
the present input, clipped to [-1, 1]) in a fixed-capacity buffer. Beside it the kernels keep
``c[i, k] = sum_{j <= i} d_j F_k(s_j-1, s_j)``, the running sum of the segment terms of
eq. 9.13 for each Everett table ``k`` (``d_j = +1`` on a rising, ``-1`` on a falling segment),
so the output costs O(1) per sample and a pop of wiped extrema costs nothing: the per-sample
cost is amortised O(1) whatever the grid size or the stack depth (O(log n) in the inverse).

``A[k]`` is an Everett table on the equally spaced grid of ``L`` levels over [-1, 1], extended
antisymmetrically (``A[i, j] = F(h_i, h_j)`` for ``i > j``, ``A[j, i] = -A[i, j]``, zero
diagonal); plain bilinear interpolation of that extension is zero on the diagonal
``alpha = beta``, as an Everett function must be (see ``model.py``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

REST_TOL = 1e-12  # relative output change below which the inverse keeps its input


@njit(cache=True, inline="always")
def _everett(A, k, a, b):
    """Bilinearly interpolated ``F_k(a, b)`` for ``-1 <= b <= a <= 1``."""
    scale = 0.5 * (A.shape[1] - 1)
    xa = (a + 1.0) * scale
    xb = (b + 1.0) * scale
    ia = min(int(xa), A.shape[1] - 2)
    ib = min(int(xb), A.shape[1] - 2)
    sa = xa - ia
    sb = xb - ib
    return ((1.0 - sa) * ((1.0 - sb) * A[k, ia, ib] + sb * A[k, ia, ib + 1])
            + sa * ((1.0 - sb) * A[k, ia + 1, ib] + sb * A[k, ia + 1, ib + 1]))


@njit(cache=True, inline="always")
def _term(A, k, p, q):
    """Segment term of eq. 9.13 for the input moving from ``p`` to ``q``."""
    if q >= p:
        return _everett(A, k, q, p)
    return -_everett(A, k, p, q)


@njit(cache=True)
def _sums(s, c, n, A):
    """Running sums ``c[0 .. n-2]`` of the staircase ``s[:n]`` (the closed segments)."""
    c[0, :] = 0.0
    for i in range(1, n - 1):
        for k in range(A.shape[0]):
            c[i, k] = c[i - 1, k] + _term(A, k, s[i - 1], s[i])


@njit(cache=True)
def _load(s, c, s0, A):
    """Copy a staircase into the buffer and build its running sums; returns its length."""
    n = s0.size
    s[:n] = s0
    _sums(s, c, n, A)
    return n


@njit(cache=True)
def _make_room(s, n):
    """Before a sample: if a push could fill the buffer, forget the innermost closed loop.

    The two entries below the last go; the staircase stays valid (the last point lies inside
    the older loops). Done before the sample, not at the push, so that the inverse searches
    on the same staircase the forward model updates.
    """
    if n >= s.size - 1:
        s[n - 3] = s[n - 1]
        n -= 2
    return n


@njit(cache=True)
def _move(s, n, u):
    """The staircase rule for the (clipped) input ``u``; returns the new length.

    A continued move replaces the last entry, a reversal pushes one; then every earlier
    extremum that ``u`` reaches or passes is wiped out together with the reversal after it.
    """
    last = s[n - 1]
    if u == last:
        return n
    if n == 1:
        s[1] = u  # from negative saturation any move is up: -1 is the lowest input
        n = 2
    elif (u > last) == (last > s[n - 2]):
        s[n - 1] = u
    else:
        s[n] = u
        n += 1
    while n >= 3:
        rising = s[n - 1] > s[n - 2]
        if (rising and s[n - 1] >= s[n - 3]) or (not rising and s[n - 1] <= s[n - 3]):
            s[n - 3] = s[n - 1]
            n -= 2
        else:
            break
    return n


@njit(cache=True)
def _update(s, c, n, u, A):
    """:func:`_move` keeping the running sums: a reversal closes the last segment, whose
    term joins ``c`` before the wiping may overwrite its ends."""
    if n > 1 and u != s[n - 1] and (u > s[n - 1]) != (s[n - 1] > s[n - 2]):
        for k in range(A.shape[0]):
            c[n - 1, k] = c[n - 2, k] + _term(A, k, s[n - 2], s[n - 1])
    return _move(s, n, u)


@njit(cache=True, inline="always")
def _table_output(A, k, s, c, n):
    """Eq. 9.13: ``-F(alpha0, beta0) + 2 * (sum of segment terms)`` for table ``k``."""
    if n == 1:
        return -A[k, A.shape[1] - 1, 0]
    return -A[k, A.shape[1] - 1, 0] + 2.0 * (c[n - 2, k] + _term(A, k, s[n - 2], s[n - 1]))


@njit(cache=True)
def run_tables(u, s0, A, capacity):
    """Relay part of every table for an input sequence.

    Returns ``P`` of shape (n_samples, K), the eq. 9.13 output of each Everett table, and the
    final staircase. With one table per Preisach cell of unit mass this is the regressor
    matrix of the least-squares fit; with the model's own tables it is the forward model.
    """
    s = np.empty(capacity)
    c = np.empty((capacity, A.shape[0]))
    n = _load(s, c, s0, A)
    out = np.empty((u.size, A.shape[0]))
    for t in range(u.size):
        # _make_room and _update written out: a numba call that passes arrays costs ~8 ns
        # here and inline="always" made it slower still (one table: 41 -> 7.4 ns/sample with
        # the loop body here, same bits). Keep in step with those two.
        if n >= capacity - 1:
            s[n - 3] = s[n - 1]
            n -= 2
        u_t = min(1.0, max(-1.0, u[t]))
        last = s[n - 1]
        if u_t != last:
            if n == 1:
                s[1] = u_t
                n = 2
            elif (u_t > last) == (last > s[n - 2]):
                s[n - 1] = u_t
            else:  # a reversal: the closed segment's term joins the running sums
                for k in range(A.shape[0]):
                    c[n - 1, k] = c[n - 2, k] + _term(A, k, s[n - 2], last)
                s[n] = u_t
                n += 1
            while n >= 3:  # wiping-out
                rising = s[n - 1] > s[n - 2]
                if (rising and s[n - 1] >= s[n - 3]) or (not rising and s[n - 1] <= s[n - 3]):
                    s[n - 3] = s[n - 1]
                    n -= 2
                else:
                    break
        for k in range(A.shape[0]):
            out[t, k] = _table_output(A, k, s, c, n)
    return out, s[:n].copy()


@njit(cache=True)
def forward(u, s0, A, weighted, poly, slope, capacity):
    """Model output over ``u``: :func:`run_tables`, then per sample the output equation
    (:func:`combine`) and the straight line of slope ``slope`` beyond [-1, 1], as
    :func:`block_forward`; returns the output and the final staircase. In one compiled loop:
    the same expression in numpy, with its temporaries, cost 5 ns/sample (8.4 -> 13.6)."""
    relay, s_end = run_tables(u, s0, A, capacity)
    y = np.empty(u.size)
    for t in range(u.size):
        u_clip = min(1.0, max(-1.0, u[t]))
        y[t] = combine(relay[t], u_clip, weighted, poly) + slope * (u[t] - u_clip)
    return y, s_end


@njit(cache=True)
def _last_index(s, start, stop, u, above):
    """Largest index ``j`` in ``start, start + 2, ... <= stop`` with ``s[j] > u`` (``above``)
    or ``s[j] < u``; -1 if none. The stored maxima fall and the minima rise along the stack
    (wiping-out), so the qualifying indices form a prefix: binary search."""
    if stop < start:
        return -1
    lo, hi = 0, (stop - start) // 2  # candidate positions j = start + 2 * m
    found = -1
    while lo <= hi:
        mid = (lo + hi) // 2
        j = start + 2 * mid
        if (s[j] > u) if above else (s[j] < u):
            found = j
            lo = mid + 1
        else:
            hi = mid - 1
    return found


@njit(cache=True, inline="always")
def _running_sum(A, k, s, c, n, i):
    """``c[i, k]``, also for ``i = n - 1`` (the still open last segment)."""
    if i <= n - 2:
        return c[i, k]
    return c[n - 2, k] + _term(A, k, s[n - 2], s[n - 1])


@njit(cache=True)
def _branch_output(u, s, c, n, A, weighted, poly, acc):
    """Model output if the input moved from the present state straight to ``u`` in [-1, 1].

    Evaluated without touching the staircase (``acc`` is scratch space): the wiped extrema
    are found by binary search, so one evaluation costs O(log n).
    """
    f0_idx = A.shape[1] - 1
    if u >= s[n - 1]:
        j = _last_index(s, 1, n - 2, u, True)  # surviving maximum above u
        i = j + 1  # its following minimum (s[0] = -1 if none survives)
        for k in range(A.shape[0]):
            base = _running_sum(A, k, s, c, n, i) if i > 0 else 0.0
            acc[k] = -A[k, f0_idx, 0] + 2.0 * (base + _everett(A, k, u, s[i]))
    else:
        i = _last_index(s, 0, n - 2, u, False)  # surviving minimum below u
        for k in range(A.shape[0]):
            if i < 0:
                acc[k] = -A[k, f0_idx, 0]
            else:
                m = i + 1
                acc[k] = -A[k, f0_idx, 0] + 2.0 * (_running_sum(A, k, s, c, n, m)
                                                    - _everett(A, k, s[m], u))
    return combine(acc, u, weighted, poly)


@njit(cache=True, inline="always")
def combine(P, u, weighted, poly):
    """Relay parts and reversible polynomial at the clipped input ``u`` (eq. 2.2 / 9.13).

    ``weighted``: the weight is interpolated between table 0 (at u = -1) and table 1 (u = +1).
    """
    if weighted:
        w = 0.5 * (1.0 + u)
        y = (1.0 - w) * P[0] + w * P[1]
    else:
        y = P[0]
    r = 0.0
    for p in range(poly.size - 1, -1, -1):  # Horner, poly[p] multiplies u**p
        r = r * u + poly[p]
    return y + r


@njit(cache=True)
def _invert_sample(target, s, c, n, A, weighted, poly, slope, tol, acc):
    """One sample of :func:`invert`: the input estimate, then the staircase updated with it.

    Returns ``(u_hat, n)``; ``s``, ``c`` are updated in place.
    """
    n = _make_room(s, n)
    last = s[n - 1]
    lo = hi = y_lo = y_hi = 0.0
    u_hat = last
    y_now = _branch_output(last, s, c, n, A, weighted, poly, acc)
    if abs(target - y_now) <= REST_TOL * max(1.0, abs(y_now)):
        # the present output to rounding (a constant output): keep the input, so that a
        # rest state stays one instead of collecting rounding-sized reversals
        target = y_now
    if target > y_now:
        lo, y_lo, hi = last, y_now, 1.0
        y_hi = _branch_output(hi, s, c, n, A, weighted, poly, acc)
        if target > y_hi:
            u_hat = 1.0 + (target - y_hi) / slope
    elif target < y_now:
        lo, hi, y_hi = -1.0, last, y_now
        y_lo = _branch_output(lo, s, c, n, A, weighted, poly, acc)
        if target < y_lo:
            u_hat = -1.0 + (target - y_lo) / slope
    inside = target != y_now and y_lo <= target <= y_hi
    if inside:
        rising = target > y_now
        for _ in range(200):
            if hi - lo <= tol:
                break
            mid = 0.5 * (lo + hi)
            y_mid = _branch_output(mid, s, c, n, A, weighted, poly, acc)
            if (y_mid < target) if rising else (y_mid <= target):
                lo, y_lo = mid, y_mid
            else:
                hi, y_hi = mid, y_mid
        u_hat = lo + (target - y_lo) * (hi - lo) / (y_hi - y_lo)
    n = _update(s, c, n, min(1.0, max(-1.0, u_hat)), A)
    return u_hat, n


@njit(cache=True)
def invert(y, s0, A, weighted, poly, slope, capacity, tol):
    """Monotone search for the input that reproduces each output sample.

    From the present state the output is continuous along the rising branch (``u`` above the
    last input) and the falling one, and monotone when the weights are non-negative. The
    target's side of the present output picks the branch; bisection keeps a bracket
    ``y(lo) < target <= y(hi)`` (rising; mirrored when falling) down to ``tol`` and finishes
    with one linear interpolation (the branches are piecewise linear in ``u``). Beyond
    saturation the model is the straight line of slope ``slope`` through the saturated output.
    """
    s = np.empty(capacity)
    c = np.empty((capacity, A.shape[0]))
    n = _load(s, c, s0, A)
    acc = np.empty(A.shape[0])
    u_hat = np.empty(y.size)
    for t in range(y.size):
        u_hat[t], n = _invert_sample(y[t], s, c, n, A, weighted, poly, slope, tol, acc)
    return u_hat, s[:n].copy()


# Loop blocks (protocol in ``hystkit.models._protocol``), shared by the classical and the
# generalised model. State slice: ``[n, s_0 .. s_{capacity-1}]``, the staircase length (a
# float) and the staircase, zero beyond ``n``. body = [capacity, L, K, weighted, slope, tol,
# n_poly, poly (n_poly), A (K L L, the antisymmetric tables)]. The running sums are rebuilt
# from the staircase every sample (O(n)): the state stays the staircase alone.

@njit(cache=True, inline="always")
def _block_parts(body):
    cap, levels, n_tab = int(body[0]), int(body[1]), int(body[2])
    n_poly = int(body[6])
    poly = body[7:7 + n_poly]
    start = 7 + n_poly
    tables = body[start:start + n_tab * levels * levels].reshape((n_tab, levels, levels))
    return cap, tables, body[3] != 0.0, body[4], body[5], poly


@njit(cache=True, inline="always")
def _block_load(x, xn, off, cap, A):
    """Copy the staircase of ``x`` into ``xn``'s slice; running sums in scratch space."""
    n = int(x[off] + 0.5)  # a count stored as a float: round, do not truncate
    s = xn[off + 1:off + 1 + cap]
    for i in range(n):
        s[i] = x[off + 1 + i]
    c = np.empty((n + 1, A.shape[0]))  # a push after _make_room writes at most row n - 1
    _sums(s, c, n, A)
    return s, c, n


@njit(cache=True, inline="always")
def _block_store(xn, off, s, n, cap):
    xn[off] = float(n)
    for i in range(n, cap):
        s[i] = 0.0


@njit(cache=True)
def block_forward(body, x, xn, off, u):
    """Staircase updated with the clipped ``u``, then eq. 9.13 / eq. 2.2 and the straight-line
    extension beyond [-1, 1] (as ``run_tables`` + the model's output equation)."""
    cap, A, weighted, slope, _, poly = _block_parts(body)
    s, c, n = _block_load(x, xn, off, cap, A)
    u_clip = min(1.0, max(-1.0, u))
    n = _make_room(s, n)
    n = _update(s, c, n, u_clip, A)
    acc = np.empty(A.shape[0])
    for k in range(A.shape[0]):
        acc[k] = _table_output(A, k, s, c, n)
    _block_store(xn, off, s, n, cap)
    return combine(acc, u_clip, weighted, poly) + slope * (u - u_clip)


@njit(cache=True)
def block_inverse(body, x, xn, off, y):
    """One sample of :func:`invert` on the staircase of ``x`` (bisection on the branch)."""
    cap, A, weighted, slope, tol, poly = _block_parts(body)
    s, c, n = _block_load(x, xn, off, cap, A)
    acc = np.empty(A.shape[0])
    u_hat, n = _invert_sample(y, s, c, n, A, weighted, poly, slope, tol, acc)
    _block_store(xn, off, s, n, cap)
    return u_hat
