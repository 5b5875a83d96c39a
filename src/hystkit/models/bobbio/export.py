"""Bobbio-Marrucci spring-piston chain (``models/bobbio/kernels.py``): ``block_forward`` /
``block_inverse`` (``invert_sample``) and the rest state (``model.rest_state``).

Body: ``[N, b, c (N), a (N - 1)]``; state: the spring forces ``F_2 .. F_N``.
"""

from __future__ import annotations

from collections.abc import Callable

from .._protocol import Translation


def extra(comp) -> dict:
    """The inverse's rest force ``(y - b) / sum(c)`` needs ``sum(c)`` (``model._rest_force``)."""
    return {"C_SUM": float(comp.params.compliance.sum())}


def state_size(plan) -> int:
    return max(1, plan.n_block_state)


def c_model(plan, lit: Callable[[float], str]) -> str:
    n = int(plan.body[0])
    total = plan.extra["C_SUM"]
    rest = ("value" if not plan.inverse else
            f"(value - BODY[1]) / {lit(total)}" if total > 0 else "R(0.0)")
    step = _C_INVERSE if plan.inverse else _C_FORWARD
    return f"""#define N_SPRINGS {n}
#define M (N_SPRINGS - 1)
#define IC 2
#define IA (2 + N_SPRINGS)

/* Apply force u: F_k+1 <- clip(F_k+1, F_k - a_k, F_k + a_k) inwards (eq. 2.5): project */
static void project(real *x, real u)
{{
    real prev = u;
    int k;
    for (k = 0; k < M; k++) {{
        real f = x[k] > prev - BODY[IA + k] ? x[k] : prev - BODY[IA + k];
        x[k] = f < prev + BODY[IA + k] ? f : prev + BODY[IA + k];
        prev = x[k];
    }}
}}

static void model_rest(real *x, real value)
{{
    int k;
    const real force = {rest};
    for (k = 0; k < M; k++) x[k] = force;
    if (M == 0) x[0] = force;  /* unused slot of a one-spring chain */
}}
{step}"""


_C_FORWARD = """
/* block_forward: project the forces with u; y = c_1 u + sum_k c_k F_k + b */
static real model_step(real *x, real u)
{
    real acc;
    int k;
    project(x, u);
    acc = BODY[IC] * u;
    for (k = 0; k < M; k++) acc += BODY[IC + 1 + k] * x[k];
    return acc + BODY[1];
}
"""

_C_INVERSE = """
/* block_inverse: walk the piecewise-linear, non-decreasing Y(F) to the force that gives y
   (kernels.invert_sample), then project; NaN (and a NaN state) where no force does */
static real model_step(real *x, real y)
{
    const real *c = BODY + IC, *a = BODY + IA;
    const real target = y - BODY[1];
    real stored = R(0.0), f;
    int k;
    for (k = 0; k < M; k++) stored += c[k + 1] * x[k];
    if (M == 0) {
        if (c[0] == R(0.0)) return (real)NAN;
        return (target - stored) / c[0];
    } else {
        const real centre = x[0], half = a[0];
        const real at_top = c[0] * (centre + half) + stored;
        const real at_bottom = c[0] * (centre - half) + stored;
        if (at_bottom <= target && target <= at_top) {
            f = c[0] == R(0.0) ? centre : (target - stored) / c[0];
        } else {
            const real s = target > at_top ? R(1.0) : R(-1.0);
            real level = s > R(0.0) ? at_top : at_bottom, slope = c[0], reach = R(0.0);
            f = centre + s * half;
            for (k = 0; k < M; k++) {
                real nxt;
                reach += a[k];
                slope += c[k + 1];
                if (k + 1 == M) break;
                nxt = x[k + 1] + s * (reach + a[k + 1]);
                if (s * (level + slope * (nxt - f)) >= s * target) break;
                level += slope * (nxt - f);
                f = nxt;
            }
            if (slope == R(0.0)) {
                for (k = 0; k < M; k++) x[k] = (real)NAN;
                return (real)NAN;
            }
            f += (target - level) / slope;
        }
    }
    project(x, f);
    return f;
}
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    total = plan.extra["C_SUM"]
    rest = ("force = value;" if not plan.inverse else
            f"force = (value - B(2)) / {lit(total)};" if total > 0 else "force = 0.0;")
    step = _M_INVERSE if plan.inverse else _M_FORWARD
    return f"""function x = model_rest(B, value)
{rest}
x = force * ones(max(1, round(B(1)) - 1), 1);
end

function x = project(B, x, u)
n = round(B(1)); ia = 2 + n;
prev = u;
for k = 1:n - 1
    x(k) = min(max(x(k), prev - B(ia + k)), prev + B(ia + k));
    prev = x(k);
end
end
{step}"""


_M_FORWARD = """
function [y, x] = model_step(B, x, u)
n = round(B(1)); ic = 2;
x = project(B, x, u);
acc = B(ic + 1) * u;
for k = 1:n - 1
    acc = acc + B(ic + 1 + k) * x(k);
end
y = acc + B(2);
end
"""

_M_INVERSE = """
function [f, x] = model_step(B, x, y)
n = round(B(1)); m = n - 1;
c = B(3:2 + n); a = B(3 + n:1 + 2 * n);
target = y - B(2);
stored = 0.0;
for k = 1:m
    stored = stored + c(k + 1) * x(k);
end
if m == 0
    if c(1) == 0, f = NaN; else, f = (target - stored) / c(1); end
    return;
end
centre = x(1); half = a(1);
at_top = c(1) * (centre + half) + stored;
at_bottom = c(1) * (centre - half) + stored;
if at_bottom <= target && target <= at_top
    if c(1) == 0, f = centre; else, f = (target - stored) / c(1); end
else
    if target > at_top, s = 1.0; level = at_top; else, s = -1.0; level = at_bottom; end
    f = centre + s * half;
    slope = c(1); reach = 0.0;
    for k = 1:m
        reach = reach + a(k);
        slope = slope + c(k + 1);
        if k == m, break; end
        nxt = x(k + 1) + s * (reach + a(k + 1));
        if s * (level + slope * (nxt - f)) >= s * target, break; end
        level = level + slope * (nxt - f);
        f = nxt;
    end
    if slope == 0
        f = NaN; x(:) = NaN;
        return;
    end
    f = f + (target - level) / slope;
end
x = project(B, x, f);
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("project",),
    extra=extra,
    state_size=state_size)
