"""Power-Law model (``models/pl/kernels.py``): ``block_forward`` (``f^-1`` of the piecewise-linear
output resistor) / ``block_inverse`` (``f``) and the rest state (``model.rest_state``).

Body: ``[n, m, i_t, power, g_lin, dt, v_b, thr (N), knee (N), w (N + 1), brk (M + 1), a (M)]``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._protocol import Translation


def extra(comp) -> dict:
    """``sum(w)``, the divisor of the inverse's rest input ``(f(y) + V_b) / sum(w)``."""
    return {"W_SUM": float(np.sum(comp.params.w))}


def c_model(plan, lit: Callable[[float], str]) -> str:
    n, m = int(plan.body[0]), int(plan.body[1])
    w_sum = plan.extra["W_SUM"]
    rest = ("value" if not plan.inverse else
            f"(f_of(value) + BODY[6]) / {lit(w_sum)}" if w_sum != 0 else "R(0.0)")
    step = _C_INVERSE if plan.inverse else _C_FORWARD
    return f"""#define N_CELLS {n}
#define N_BASIS {m}
#define IW (7 + 2 * N_CELLS)
#define IB (IW + N_CELLS + 1)
#define IS (IB + N_BASIS + 1)

/* Cell resistor current: odd power law inside the knee (eq. 2.16), straight line outside */
static real current(real v, int k)
{{
    const real i_t = BODY[2], power = BODY[3], g_lin = BODY[4];
    const real thr = BODY[7 + k], knee = BODY[7 + N_CELLS + k];
    const real a = FABS(v), s = v >= R(0.0) ? R(1.0) : R(-1.0);
    const real scale = i_t / (power - R(1.0));
    if (a <= knee) return s * scale * POW(a / thr, power);
    return s * (scale * POW(knee / thr, power) + g_lin * (a - knee));
}}

static void cells(real *x, real drive)
{{
    int k;
    for (k = 0; k < N_CELLS; k++) x[k] = x[k] + current(drive - x[k], k) * BODY[5];
}}
{_C_F if plan.inverse else _C_F_INVERSE}
static void model_rest(real *x, real value)
{{
    int k;
    const real v = {rest};
    for (k = 0; k < N_CELLS; k++) x[k] = v;
}}
{step}"""


_C_F = """
/* u = f(i) = sum_j a_j phi_j(i), the outermost segments unbounded (eq. 2.17): kernels._f */
static real f_of(real i)
{
    real total = R(0.0);
    int j;
    for (j = 0; j < N_BASIS; j++) {
        const real lo = j == 0 ? -(real)HUGE_VAL : BODY[IB + j];
        const real hi = j == N_BASIS - 1 ? (real)HUGE_VAL : BODY[IB + j + 1];
        const real ci = i > lo ? (i < hi ? i : hi) : (lo < hi ? lo : hi);
        const real c0 = R(0.0) > lo ? (R(0.0) < hi ? R(0.0) : hi) : (lo < hi ? lo : hi);
        total += BODY[IS + j] * (ci - c0);
    }
    return total;
}
"""

_C_F_INVERSE = """
/* i = f^-1(u) for the increasing PWL f with f(0) = 0 (eq. 2.18): kernels._f_inverse */
static real f_inverse(real u)
{
    const real *brk = BODY + IB, *a = BODY + IS;
    int j0 = 0, j;
    real f_left = R(0.0), i_left = R(0.0);
    while (j0 < N_BASIS - 1 && brk[j0 + 1] <= R(0.0)) j0++;
    j = j0;
    if (u >= R(0.0)) {
        while (j < N_BASIS - 1 && f_left + a[j] * (brk[j + 1] - i_left) < u) {
            f_left += a[j] * (brk[j + 1] - i_left);
            i_left = brk[j + 1];
            j++;
        }
        return i_left + (u - f_left) / a[j];
    }
    while (j > 0 && f_left - a[j] * (i_left - brk[j]) > u) {
        f_left -= a[j] * (i_left - brk[j]);
        i_left = brk[j];
        j--;
    }
    return i_left + (u - f_left) / a[j];
}
"""

_C_FORWARD = """
/* block_forward: i = f^-1(w_0 e + sum w_k u_k - V_b) (eq. 2.18), then the cells driven by e */
static real model_step(real *x, real u)
{
    int k;
    real acc = BODY[IW] * u - BODY[6], y;
    for (k = 0; k < N_CELLS; k++) acc += BODY[IW + 1 + k] * x[k];
    y = f_inverse(acc);
    cells(x, u);
    return y;
}
"""

_C_INVERSE = """
/* block_inverse: e = (f(i) + V_b - sum w_k u_k) / w_0 (eq. 2.17, 2.20), cells driven by e */
static real model_step(real *x, real y)
{
    int k;
    real acc = f_of(y) + BODY[6], e;
    for (k = 0; k < N_CELLS; k++) acc -= BODY[IW + 1 + k] * x[k];
    e = acc / BODY[IW];
    cells(x, e);
    return e;
}
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    w_sum = plan.extra["W_SUM"]
    rest = ("v = value;" if not plan.inverse else
            f"v = (f_of(B, value) + B(7)) / {lit(w_sum)};" if w_sum != 0 else "v = 0.0;")
    step = _M_INVERSE if plan.inverse else _M_FORWARD
    return f"""function x = model_rest(B, value)
{rest}
x = v * ones(round(B(1)), 1);
end

function [n, m, iw, ib, is_] = layout(B)
n = round(B(1)); m = round(B(2));
iw = 8 + 2 * n; ib = iw + n + 1; is_ = ib + m + 1;
end

function f = current(B, v, k)
n = round(B(1));
i_t = B(3); power = B(4); g_lin = B(5); thr = B(7 + k); knee = B(7 + n + k);
a = abs(v);
if v >= 0, s = 1.0; else, s = -1.0; end
scale = i_t / (power - 1.0);
if a <= knee
    f = s * scale * (a / thr) ^ power;
else
    f = s * (scale * (knee / thr) ^ power + g_lin * (a - knee));
end
end

function x = cells(B, x, drive)
for k = 1:round(B(1))
    x(k) = x(k) + current(B, drive - x(k), k) * B(6);
end
end

function total = f_of(B, i)
[n, m, iw, ib, is_] = layout(B);
total = 0.0;
for j = 1:m
    if j == 1, lo = -Inf; else, lo = B(ib + j - 1); end
    if j == m, hi = Inf; else, hi = B(ib + j); end
    total = total + B(is_ + j - 1) * (min(max(i, lo), hi) - min(max(0.0, lo), hi));
end
end

function i = f_inverse(B, u)
[n, m, iw, ib, is_] = layout(B);
brk = B(ib:ib + m); a = B(is_:is_ + m - 1);
j = 1;
while j < m && brk(j + 1) <= 0
    j = j + 1;
end
f_left = 0.0; i_left = 0.0;
if u >= 0
    while j < m && f_left + a(j) * (brk(j + 1) - i_left) < u
        f_left = f_left + a(j) * (brk(j + 1) - i_left);
        i_left = brk(j + 1);
        j = j + 1;
    end
else
    while j > 1 && f_left - a(j) * (i_left - brk(j)) > u
        f_left = f_left - a(j) * (i_left - brk(j));
        i_left = brk(j);
        j = j - 1;
    end
end
i = i_left + (u - f_left) / a(j);
end
{step}"""


_M_FORWARD = """
function [y, x] = model_step(B, x, u)
[n, m, iw] = layout(B);
acc = B(iw) * u - B(7);
for k = 1:n
    acc = acc + B(iw + k) * x(k);
end
y = f_inverse(B, acc);
x = cells(B, x, u);
end
"""

_M_INVERSE = """
function [e, x] = model_step(B, x, y)
[n, m, iw] = layout(B);
acc = f_of(B, y) + B(7);
for k = 1:n
    acc = acc - B(iw + k) * x(k);
end
e = acc / B(iw);
x = cells(B, x, e);
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("cells", "current", "f_inverse", "f_of", "layout"),
    extra=extra)
