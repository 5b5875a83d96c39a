"""mPL (``models/mpl/kernels.py``): ``block_forward`` / ``block_inverse`` and the rest state.

Body: ``[n, v_b, cap, dt, i_s (n), v_t (n), knee (n), w (n + 1)]``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._protocol import Translation


def extra(comp) -> dict:
    """``W_SUM``: ``sum(w)``, the divisor of the inverse's rest input ``(y + V_b) / sum(w)``."""
    return {"W_SUM": float(np.sum(comp.params.w))}


def c_model(plan, lit: Callable[[float], str]) -> str:
    n = int(plan.body[0])
    w_sum = plan.extra["W_SUM"]
    rest = ("x[k] = value;" if not plan.inverse else  # mpl.invert's start
            f"x[k] = (value + BODY[1]) / {lit(w_sum)};" if w_sum != 0 else "x[k] = R(0.0);")
    if plan.inverse:
        head = """    real acc = u + BODY[1];
    for (k = 0; k < N_CELLS; k++) acc -= BODY[IW + 1 + k] * x[k];
    drive = acc / BODY[IW];"""
    else:
        head = """    real acc = BODY[IW] * u - BODY[1];
    for (k = 0; k < N_CELLS; k++) acc += BODY[IW + 1 + k] * x[k];
    drive = u;"""
    out = "drive" if plan.inverse else "acc"
    return f"""#define N_CELLS {n}
#define IW (4 + 3 * N_CELLS)

/* Limited sinh resistor current (eq. 5.1 with eq. 5.29): kernels.current */
static real current(real v, int k)
{{
    const real i_s = BODY[4 + k], v_t = BODY[4 + N_CELLS + k];
    const real knee = BODY[4 + 2 * N_CELLS + k], cap = BODY[2];
    real s;
    if (FABS(v) <= knee) return R(2.0) * i_s * SINH(v / v_t);
    s = v > R(0.0) ? R(1.0) : R(-1.0);
    return s * R(2.0) * i_s * SINH(knee / v_t) + cap * (v - s * knee);
}}

static void model_rest(real *x, real value)
{{
    int k;
    for (k = 0; k < N_CELLS; k++) {rest}
}}

/* {'block_inverse: u_hat = (y + V_b - sum w_k x_k) / w_0 (eq. 5.13)' if plan.inverse else
   'block_forward: y = w_0 u + sum w_k x_k - V_b (eq. 5.2)'}, then the cells (eq. 5.6) */
static real model_step(real *x, real u)
{{
    int k;
    real drive;
{head}
    for (k = 0; k < N_CELLS; k++) x[k] = x[k] + current(drive - x[k], k) * BODY[3];
    return {out};
}}
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    w_sum = plan.extra["W_SUM"]
    rest = ("v = value;" if not plan.inverse else
            f"v = (value + B(2)) / {lit(w_sum)};" if w_sum != 0 else "v = 0.0;")
    if plan.inverse:
        head = """acc = u + B(2);
for k = 1:n
    acc = acc - B(iw + k) * x(k);
end
drive = acc / B(iw);
out = drive;"""
    else:
        head = """acc = B(iw) * u - B(2);
for k = 1:n
    acc = acc + B(iw + k) * x(k);
end
drive = u;
out = acc;"""
    return f"""function x = model_rest(B, value)
{rest}
x = v * ones(round(B(1)), 1);
end

function [out, x] = model_step(B, x, u)
n = round(B(1));
iw = 5 + 3 * n;
{head}
for k = 1:n
    x(k) = x(k) + mpl_current(B, drive - x(k), k, n) * B(4);
end
end

function f = mpl_current(B, v, k, n)
i_s = B(4 + k); v_t = B(4 + n + k); knee = B(4 + 2 * n + k); cap = B(3);
if abs(v) <= knee
    f = 2.0 * i_s * sinh(v / v_t);
else
    s = -1.0; if v > 0, s = 1.0; end
    f = s * 2.0 * i_s * sinh(knee / v_t) + cap * (v - s * knee);
end
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("mpl_current",),
    extra=extra)
