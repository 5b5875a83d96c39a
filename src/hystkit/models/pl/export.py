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
    """MATLAB on every cell and segment at once (Octave interprets each statement and call):
    the body's layout written in at export, sums in the C's order (``sum`` adds left to right
    from the first term; x - a is x + -a)."""
    w_sum = plan.extra["W_SUM"]
    n, m = int(plan.body[0]), int(plan.body[1])
    i_w = 8 + 2 * n
    i_b = i_w + n + 1
    i_s = i_b + m + 1
    rest = ("v = value;" if not plan.inverse else
            f"v = (f_of(B, value) + B(7)) / {lit(w_sum)};" if w_sum != 0 else "v = 0.0;")
    step = _M_INVERSE if plan.inverse else _M_FORWARD
    code = f"""function x = model_rest(B, value)
{rest}
x = v * ones(round(B(1)), 1);
end

function x = cells(B, x, drive)
% every cell's current (power law up to the knee, then straight), the Euler step
v = drive - x;
thr = B(8:@N7@); knee = B(@N8@:@N2_7@); power = B(4);
a = abs(v);
s = 2.0 * (v >= 0) - 1.0;
scale = B(3) / (power - 1.0);
f = s .* scale .* (a ./ thr) .^ power;
far = ~(a <= knee);
if any(far)
    f(far) = s(far) .* (scale * (knee(far) ./ thr(far)) .^ power + B(5) * (a(far) - knee(far)));
end
x = x + f * B(6);
end

function total = f_of(B, i)
% the segments j = 1 .. m between the breakpoints (open at both ends)
lo = [-Inf; B(@IB1@:@IBM@)]; hi = [B(@IB1@:@IBM@); Inf];
total = sum(B(@IS@:@ISM@) .* (min(max(i, lo), hi) - min(max(0.0, lo), hi)));
end

function i = f_inverse(B, u)
m = @M@;
brk = B(@IB@:@IBE@); a = B(@IS@:@ISM@);
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
    spans = {"@N7@": str(7 + n), "@N8@": str(8 + n), "@N2_7@": str(7 + 2 * n),
             "@IB1@": str(i_b + 1), "@IBM@": str(i_b + m - 1), "@IBE@": str(i_b + m),
             "@IB@": str(i_b), "@IS@": str(i_s), "@ISM@": str(i_s + m - 1), "@M@": str(m),
             "@IW@": str(i_w), "@IWN@": f"{i_w + 1}:{i_w + n}"}
    for key, value in spans.items():
        code = code.replace(key, value)
    return code


_M_FORWARD = """
function [y, x] = model_step(B, x, u)
y = f_inverse(B, sum([B(@IW@) * u - B(7); B(@IWN@) .* x]));
x = cells(B, x, u);
end
"""

_M_INVERSE = """
function [e, x] = model_step(B, x, y)
e = sum([f_of(B, y) + B(7); -(B(@IWN@) .* x)]) / B(@IW@);
x = cells(B, x, e);
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("cells", "f_inverse", "f_of"),
    extra=extra)
