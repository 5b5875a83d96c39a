"""Chua-Stromsmoe model (``models/chua/kernels.py``): ``block_forward`` / ``block_inverse``
(bisection on the input) and the rest state (``model.rest_state``: ``f_k^-1`` by bisection).

Body: ``[N, dt, k0 (N), k_inf (N), y_s (N), g (N), v_g (N), delta (N), knee (N), cap (N)]``;
state: the element outputs ``y_k``.

One addition to the kernels: every bisection also stops when the midpoint no longer lies
strictly inside the bracket. In double the kernels' relative tolerances end the loops long
before (the numbers do not change); in float they are below the resolution and would not.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._protocol import Translation

REST_TOL = 1e-12  # kernels.REST_TOL
FLOAT_TOL = 2e-6  # in float, REST_TOL is below the resolution: ~16 float epsilons instead


def extra(comp) -> dict:
    """The bracket of ``kernels.rest_input``: ``max(max(k0, k_inf))``,
    ``max(|k0 - k_inf| y_s)``."""
    p = comp.params
    return {"MAX_K": float(np.max(np.maximum(p.k0, p.k_inf))),
            "MAX_SPREAD": float(np.max(np.abs(p.k0 - p.k_inf) * p.y_s))}


def c_model(plan, lit: Callable[[float], str]) -> str:
    n = int(plan.body[0])
    e = plan.extra
    value = ("rest_input(value)" if plan.inverse else "value")
    rest_input = f"""
/* The common input whose rest states sum to y0 (increasing): kernels.rest_input */
static real rest_input(real y0)
{{
    const real span = (FABS(y0) + R(1.0)) * {lit(e['MAX_K'])} + {lit(e['MAX_SPREAD'])};
    real lo = -span * (real)N_EL, hi = span * (real)N_EL;
    while (hi - lo > R(1e-16) * (R(1.0) + FABS(lo) + FABS(hi))) {{
        const real mid = R(0.5) * (lo + hi);
        real total = R(0.0);
        int k;
        if (mid <= lo || mid >= hi) break;
        for (k = 0; k < N_EL; k++) total += restoring_inverse(mid, k);
        if (total >= y0) hi = mid;
        else lo = mid;
    }}
    return R(0.5) * (lo + hi);
}}
""" if plan.inverse else ""
    step = _C_INVERSE if plan.inverse else _C_FORWARD
    tol = REST_TOL if not lit(0.5).endswith("f") else FLOAT_TOL  # the literal's precision
    return f"""#define N_EL {n}
#define REST_TOL {lit(tol)}
#define P(i, k) BODY[2 + (i) * N_EL + (k)]  /* parameter i of element k */

/* Restoring function f: odd, slope k0 at 0 and k_inf far out */
static real restoring(real y, int k)
{{
    return P(1, k) * y + (P(0, k) - P(1, k)) * P(2, k) * TANH(y / P(2, k));
}}

/* f_k^-1(u) by bisection: kernels.restoring_inverse */
static real restoring_inverse(real u, int k)
{{
    const real spread = FABS(P(0, k) - P(1, k)) * P(2, k);
    real lo = (u - spread) / P(1, k), hi = (u + spread) / P(1, k);
    while (hi - lo > R(1e-16) * (R(1.0) + FABS(lo) + FABS(hi))) {{
        const real mid = R(0.5) * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        if (restoring(mid, k) >= u) hi = mid;
        else lo = mid;
    }}
    return R(0.5) * (lo + hi);
}}

/* Limited dissipation function g: dead band, sinh, straight line of slope cap */
static real dissipation(real v, int k)
{{
    const real g = P(3, k), v_g = P(4, k), band = P(5, k), knee = P(6, k), cap = P(7, k);
    const real a = FABS(v);
    real s;
    if (a <= band) return R(0.0);
    s = v > R(0.0) ? R(1.0) : R(-1.0);
    if (a <= knee) return s * g * v_g * SINH((a - band) / v_g);
    return s * (g * v_g * SINH((knee - band) / v_g) + cap * (a - knee));
}}
{rest_input}
static void model_rest(real *x, real value)
{{
    const real u = {value};
    int k;
    for (k = 0; k < N_EL; k++) x[k] = restoring_inverse(u, k);
}}
{step}"""


_C_FORWARD = """
/* block_forward: Euler step of every element driven by u; the output is the sum of the new
   states (kernels.advance) */
static real model_step(real *x, real u)
{
    real acc = R(0.0);
    int k;
    for (k = 0; k < N_EL; k++) {
        const real v = u - restoring(x[k], k);
        x[k] = x[k] + BODY[1] * dissipation(v, k);
        acc += x[k];
    }
    return acc;
}
"""

_C_INVERSE = """
/* Smallest (upper 0) or largest v with g(v) = r: kernels._dissipation_inverse */
static real dissipation_inverse(real r, int k, int upper)
{
    const real g = P(3, k), v_g = P(4, k), band = P(5, k), knee = P(6, k), cap = P(7, k);
    real s, a, g_knee;
    if (r == R(0.0)) return upper ? band : -band;
    s = r > R(0.0) ? R(1.0) : R(-1.0);
    a = FABS(r);
    g_knee = g * v_g * SINH((knee - band) / v_g);
    if (a <= g_knee) return s * (band + v_g * ASINH(a / (g * v_g)));
    return s * (knee + (a - g_knee) / cap);
}

/* block_inverse: the input u with sum_k g_k(u - f_k(x_k)) = (y - sum x) / dt by bisection
   (kernels.solve_input), then the Euler step it gives (kernels.invert_sample) */
static real model_step(real *x, real y)
{
    real fx[N_EL], total = R(0.0), scale = R(0.0), r, lo = (real)HUGE_VAL,
         hi = -(real)HUGE_VAL, ends[2], e;
    int k, side;
    for (k = 0; k < N_EL; k++) {
        fx[k] = restoring(x[k], k);
        total += x[k];
        scale += FABS(x[k]);
    }
    /* the present output to rounding: no element moves (kernels.REST_TOL) */
    if (FABS(y) > scale) scale = FABS(y);
    if (scale < R(1.0)) scale = R(1.0);
    if (FABS(y - total) <= REST_TOL * scale) y = total;
    r = (y - total) / BODY[1];
    for (k = 0; k < N_EL; k++) {
        const real l = fx[k] + dissipation_inverse(r / (real)N_EL, k, 0);
        const real h = fx[k] + dissipation_inverse(r / (real)N_EL, k, 1);
        if (l < lo) lo = l;
        if (h > hi) hi = h;
    }
    for (side = 0; side < 2; side++) {
        real a = lo, b = hi;
        while (b - a > R(1e-14) * (R(1.0) + FABS(a) + FABS(b))) {
            const real m = R(0.5) * (a + b);
            real rate = R(0.0);
            if (m <= a || m >= b) break;
            for (k = 0; k < N_EL; k++) rate += dissipation(m - fx[k], k);
            if (rate > r || (side == 0 && rate == r)) b = m;
            else a = m;
        }
        ends[side] = side == 0 ? b : a;
    }
    e = R(0.5) * (ends[0] + ends[1]);
    for (k = 0; k < N_EL; k++) x[k] = x[k] + BODY[1] * dissipation(e - fx[k], k);
    return e;
}
"""


# MATLAB works on all elements at once (column vectors): Octave interprets every statement
# and call, so a bisection step is two array statements instead of a call per element and
# parameter. Each element's arithmetic is the scalar C's, operation for operation (s * g * v_g
# * sinh(t) equals s * ((g * v_g) * sinh(t) + 0) for s = +-1), so the numbers are the same.

def _m_params(n: int) -> str:
    names = ("k0", "k_inf", "y_s", "g", "v_g", "band", "knee", "cap")
    slices = "\n".join(f"{name} = B({3 + i * n}:{2 + (i + 1) * n});"
                       for i, name in enumerate(names))
    return f"""function [k0, k_inf, y_s, gv, v_g, band, knee, cap, gk] = params(B)
% every element's parameters (body [N, dt, k0, k_inf, y_s, g, v_g, delta, knee, cap]), gv = g
% v_g and gk, the dissipation at the knee
{slices}
gv = g .* v_g;
gk = gv .* sinh((knee - band) ./ v_g);
end
"""


# g_k(v_k) of every element, a = |v|: 0 in the dead band, the sinh up to the knee, then the
# straight line (kernels._dissipation; knee >= band; a NaN v gives NaN, as there)
_M_DISSIPATION = ("(2.0 * (v > 0) - 1.0) .* (gv .* sinh((min(max(a, band), knee) - band) ./ v_g)"
                  " + cap .* ((a - knee) .* (a > knee)))")

_M_COMMON = """function f = restoring(y, k0, k_inf, y_s)
f = k_inf .* y + (k0 - k_inf) .* y_s .* tanh(y ./ y_s);
end

function y = restoring_inverse(u, k0, k_inf, y_s)
% f_k^-1(u) of every element, each its own bisection (kernels.restoring_inverse)
spread = abs(k0 - k_inf) .* y_s;
lo = (u - spread) ./ k_inf; hi = (u + spread) ./ k_inf;
go = hi - lo > 1e-16 * (1.0 + abs(lo) + abs(hi));
while any(go)
    mid = 0.5 * (lo + hi);
    go = go & ~(mid <= lo | mid >= hi);
    up = go & (restoring(mid, k0, k_inf, y_s) >= u);
    down = go & ~up;
    hi(up) = mid(up);
    lo(down) = mid(down);
    go = go & (hi - lo > 1e-16 * (1.0 + abs(lo) + abs(hi)));
end
y = 0.5 * (lo + hi);
end

function d = dissipation(v, gv, v_g, band, knee, cap)
a = abs(v);
d = @DISSIPATION@;
end
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    e = plan.extra
    value = "rest_input(value, k0, k_inf, y_s)" if plan.inverse else "value"
    step = (_M_INVERSE.replace("@MAXK@", lit(e["MAX_K"])).replace("@MAXS@",
                                                                   lit(e["MAX_SPREAD"]))
            .replace("@RT@", lit(REST_TOL)) if plan.inverse else _M_FORWARD)
    return (f"""function x = model_rest(B, value)
[k0, k_inf, y_s] = params(B);
x = restoring_inverse({value}, k0, k_inf, y_s);
end

{_m_params(int(plan.body[0]))}
""" + _M_COMMON + step).replace("@DISSIPATION@", _M_DISSIPATION)


_M_FORWARD = """
function [acc, x] = model_step(B, x, u)
[k0, k_inf, y_s, gv, v_g, band, knee, cap] = params(B);
x = x + B(2) * dissipation(u - restoring(x, k0, k_inf, y_s), gv, v_g, band, knee, cap);
acc = sum(x);
end
"""

# The two bisections (first u with rate >= r, last with rate <= r) take the same steps until
# a rate equals r: without such a tie the second one's end is the first one's lower end.
_M_INVERSE = """
function u = rest_input(y0, k0, k_inf, y_s)
n = numel(k0);
span = (abs(y0) + 1.0) * @MAXK@ + @MAXS@;
lo = -span * n; hi = span * n;
while hi - lo > 1e-16 * (1.0 + abs(lo) + abs(hi))
    mid = 0.5 * (lo + hi);
    if mid <= lo || mid >= hi, break; end
    if sum(restoring_inverse(mid, k0, k_inf, y_s)) >= y0, hi = mid; else, lo = mid; end
end
u = 0.5 * (lo + hi);
end

function v = dissipation_inverse(r, gv, v_g, band, knee, cap, gk, upper)
% the smallest (upper false) or largest v_k with g_k(v_k) = r, every element
if r == 0
    if upper, v = band; else, v = -band; end
    return;
end
if r > 0, s = 1.0; else, s = -1.0; end
a = abs(r);
v = s * (band + v_g .* asinh(a ./ gv));
far = ~(a <= gk);
v(far) = s * (knee(far) + (a - gk(far)) ./ cap(far));
end

function [e, x] = model_step(B, x, y)
[k0, k_inf, y_s, gv, v_g, band, knee, cap, gk] = params(B);
n = numel(x); dt = B(2);
fx = restoring(x, k0, k_inf, y_s);
total = sum(x);
if abs(y - total) <= @RT@ * max([1.0, abs(y), sum(abs(x))]), y = total; end
r = (y - total) / dt;
lo = min(fx + dissipation_inverse(r / n, gv, v_g, band, knee, cap, gk, false));
hi = max(fx + dissipation_inverse(r / n, gv, v_g, band, knee, cap, gk, true));
ends = [0.0, 0.0];
tie = false;
for side = 0:1
    if side == 1 && ~tie
        ends(2) = a_;
        break;
    end
    a_ = lo; b_ = hi;
    while b_ - a_ > 1e-14 * (1.0 + abs(a_) + abs(b_))
        m = 0.5 * (a_ + b_);
        if m <= a_ || m >= b_, break; end
        v = m - fx;
        a = abs(v);
        rate = sum(@DISSIPATION@);
        if rate > r
            b_ = m;
        elseif rate == r
            tie = true;
            if side == 0, b_ = m; else, a_ = m; end
        else
            a_ = m;
        end
    end
    if side == 0, ends(1) = b_; else, ends(2) = a_; end
end
e = 0.5 * (ends(1) + ends(2));
x = x + dt * dissipation(e - fx, gv, v_g, band, knee, cap);
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("dissipation", "dissipation_inverse", "params", "rest_input", "restoring",
                 "restoring_inverse"),
    extra=extra)
