"""Prandtl-Ishlinskii with creep (``models/pi/kernels.py``): ``block_forward`` /
``block_inverse`` (on the forward state) and the rest state (``model.rest_state``).

Forward body: ``[n, m, k, b, r (n), w_h (n), c (m), w_k (m), d_s (k), w_s (k)]``; inverse body:
``[n, m, k, sign b, r, w_h, c, sign w_k, d_inv (k), sign ws_inv (k), r_inv (n), w_inv (n),
sign w~ (n)]``. State: plays ``p (n)``, then creep states ``z (m)``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._protocol import Translation
from .operators import inverse_superposition


def extra(comp) -> dict:
    """The inverse's rest input ``(S^-1(y0) - b) / (sum w_H + sum w_K)`` (``model.rest_input``)
    needs the unsigned ``S^-1`` weights, ``b`` and the static gain."""
    p = comp.params
    d_inv, ws_inv = inverse_superposition(p.d_s, p.w_s)
    return {"GAIN": float(p.w_h.sum() + p.w_k.sum()), "B": float(p.b),
            "D_INV": np.asarray(d_inv, float), "WS_INV": np.asarray(ws_inv, float)}


def _c_array(name, values, lit) -> str:
    items = ", ".join(lit(v) for v in np.asarray(values, float).ravel())
    return f"static const real {name}[{max(1, np.size(values))}] = {{{items}}};"


def c_model(plan, lit: Callable[[float], str]) -> str:
    n, m, k = (int(v) for v in plan.body[:3])
    e = plan.extra
    if plan.inverse:
        rest_consts = (_c_array("REST_D", e["D_INV"], lit) + "\n"
                       + _c_array("REST_W", e["WS_INV"], lit) + "\n")
        rest = f"(superposition(value, REST_D, REST_W, {k}) - {lit(e['B'])}) / {lit(e['GAIN'])}"
    else:
        rest_consts, rest = "", "value"
    step = _C_INVERSE if plan.inverse else _C_FORWARD
    return f"""#define N_PLAY {n}
#define N_CREEP {m}
#define N_DZ {k}
#define I_R 4
#define I_WH (I_R + N_PLAY)
#define I_C (I_R + 2 * N_PLAY)
#define I_WK (I_C + N_CREEP)
#define I_D (I_C + 2 * N_CREEP)
#define I_WD (I_D + N_DZ)
#define I_RINV (I_D + 2 * N_DZ)
#define I_WINV (I_RINV + N_PLAY)
#define I_W (I_WINV + N_PLAY)

static real max2(real a, real b) {{ return b > a ? b : a; }}
static real min2(real a, real b) {{ return b < a ? b : a; }}

/* One-sided dead zones weighted and summed (eq. 2.12): kernels._superposition */
static real superposition(real v, const real *d, const real *w, int n_dz)
{{
    real acc = R(0.0);
    int j;
    for (j = 0; j < n_dz; j++) {{
        if (d[j] > R(0.0)) acc += w[j] * max2(v - d[j], R(0.0));
        else if (d[j] < R(0.0)) acc += w[j] * min2(v - d[j], R(0.0));
        else acc += w[j] * v;
    }}
    return acc;
}}

/* Plays (eq. 2.11) and creep states moved by the input: kernels._move */
static void move(real *x, real u)
{{
    int i;
    for (i = 0; i < N_PLAY; i++)
        x[i] = max2(u - BODY[I_R + i], min2(u + BODY[I_R + i], x[i]));
    for (i = 0; i < N_CREEP; i++)
        x[N_PLAY + i] += BODY[I_C + i] * (u - x[N_PLAY + i]);
}}
{rest_consts}
static void model_rest(real *x, real value)
{{
    int i;
    const real u = {rest};
    for (i = 0; i < N_PLAY + N_CREEP; i++) x[i] = u;
}}
{step}"""


_C_FORWARD = """
/* block_forward: states moved by u, then y = S[H + K + b] (eq. 2.12-2.15) */
static real model_step(real *x, real u)
{
    int i;
    real v = BODY[3];
    move(x, u);
    for (i = 0; i < N_PLAY; i++) v += BODY[I_WH + i] * x[i];
    for (i = 0; i < N_CREEP; i++) v += BODY[I_WK + i] * x[N_PLAY + i];
    return superposition(v, BODY + I_D, BODY + I_WD, N_DZ);
}
"""

_C_INVERSE = """
/* block_inverse: the inverse plays of sign * H~ from the present plays (eq. 2.19), then the
   forward state moved by the estimate */
static real model_step(real *x, real y)
{
    int j;
    real big_w = R(0.0), v, u_hat = R(0.0), tail = R(0.0);
    for (j = 0; j < N_PLAY; j++) big_w += BODY[I_W + j];
    v = superposition(y, BODY + I_D, BODY + I_WD, N_DZ) - BODY[3];
    for (j = 0; j < N_CREEP; j++)
        v -= BODY[I_WK + j] * (R(1.0) - BODY[I_C + j]) * x[N_PLAY + j];
    for (j = N_PLAY - 1; j >= 0; j--) {
        const real p_j = x[j];
        const real q = big_w * p_j + tail;
        u_hat += BODY[I_WINV + j] * max2(v - BODY[I_RINV + j], min2(v + BODY[I_RINV + j], q));
        tail += BODY[I_W + j] * p_j;
        big_w -= BODY[I_W + j];
    }
    move(x, u_hat);
    return u_hat;
}
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    e = plan.extra

    def col(values):
        return "[" + ", ".join(lit(v) for v in np.asarray(values, float).ravel()) + "]"

    rest = (f"u = (superposition(value, {col(e['D_INV'])}, {col(e['WS_INV'])}) - "
            f"{lit(e['B'])}) / {lit(e['GAIN'])};" if plan.inverse else "u = value;")
    step = _M_INVERSE if plan.inverse else _M_FORWARD
    return f"""function x = model_rest(B, value)
{rest}
x = u * ones(round(B(1)) + round(B(2)), 1);
end

function [n, m, k, ir, iwh, ic, iwk, id, iwd] = layout(B)
n = round(B(1)); m = round(B(2)); k = round(B(3));
ir = 4; iwh = ir + n; ic = ir + 2 * n; iwk = ic + m; id = ic + 2 * m; iwd = id + k;
end

function acc = superposition(v, d, w)
acc = 0.0;
for j = 1:numel(d)
    if d(j) > 0
        acc = acc + w(j) * max(v - d(j), 0.0);
    elseif d(j) < 0
        acc = acc + w(j) * min(v - d(j), 0.0);
    else
        acc = acc + w(j) * v;
    end
end
end

function x = move(B, x, u)
[n, m, k, ir, iwh, ic] = layout(B);
for i = 1:n
    x(i) = max(u - B(ir + i), min(u + B(ir + i), x(i)));
end
for i = 1:m
    x(n + i) = x(n + i) + B(ic + i) * (u - x(n + i));
end
end
{step}"""


_M_FORWARD = """
function [y, x] = model_step(B, x, u)
[n, m, k, ir, iwh, ic, iwk, id, iwd] = layout(B);
x = move(B, x, u);
v = B(4);
for i = 1:n
    v = v + B(iwh + i) * x(i);
end
for i = 1:m
    v = v + B(iwk + i) * x(n + i);
end
y = superposition(v, B(id + 1:id + k), B(iwd + 1:iwd + k));
end
"""

_M_INVERSE = """
function [u_hat, x] = model_step(B, x, y)
[n, m, k, ir, iwh, ic, iwk, id, iwd] = layout(B);
irinv = id + 2 * k; iwinv = irinv + n; iw = iwinv + n;
big_w = 0.0;
for j = 1:n
    big_w = big_w + B(iw + j);
end
v = superposition(y, B(id + 1:id + k), B(iwd + 1:iwd + k)) - B(4);
for j = 1:m
    v = v - B(iwk + j) * (1.0 - B(ic + j)) * x(n + j);
end
u_hat = 0.0;
tail = 0.0;
for j = n:-1:1
    p_j = x(j);
    q = big_w * p_j + tail;
    u_hat = u_hat + B(iwinv + j) * max(v - B(irinv + j), min(v + B(irinv + j), q));
    tail = tail + B(iw + j) * p_j;
    big_w = big_w - B(iw + j);
end
x = move(B, x, u_hat);
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("layout", "move", "superposition"),
    extra=extra)
