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
    """MATLAB on every play and creep state at once (Octave interprets each statement and
    call): the body's index ranges are written in, the sums taken in the C's order (``sum``
    and ``cumsum`` add left to right from the first term; x - a is x + -a)."""
    n, m, k = (int(v) for v in plan.body[:3])
    e = plan.extra

    def col(values):
        return "[" + ", ".join(lit(v) for v in np.asarray(values, float).ravel()) + "]"

    i_r, i_c = 4, 4 + 2 * n
    i_d = i_c + 2 * m
    i_rinv = i_d + 2 * k
    spans = {"@P@": f"1:{n}", "@Z@": f"{n + 1}:{n + m}", "@R@": f"{i_r + 1}:{i_r + n}",
             "@WH@": f"{i_r + n + 1}:{i_r + 2 * n}", "@C@": f"{i_c + 1}:{i_c + m}",
             "@WK@": f"{i_c + m + 1}:{i_c + 2 * m}", "@D@": f"{i_d + 1}:{i_d + k}",
             "@WD@": f"{i_d + k + 1}:{i_d + 2 * k}",
             "@RINV@": f"{i_rinv + n}:-1:{i_rinv + 1}",
             "@WINV@": f"{i_rinv + 2 * n}:-1:{i_rinv + n + 1}",
             "@W@": f"{i_rinv + 2 * n + 1}:{i_rinv + 3 * n}", "@N@": str(n)}
    rest = (f"u = (superposition(value, {col(e['D_INV'])}, {col(e['WS_INV'])}) - "
            f"{lit(e['B'])}) / {lit(e['GAIN'])};" if plan.inverse else "u = value;")
    code = f"""function x = model_rest(B, value)
{rest}
x = u * ones({n + m}, 1);
end

function acc = superposition(v, d, w)
% the one-sided dead zones d weighted by w, summed in order
t = w * v;
up = d > 0;
t(up) = w(up) .* max(v - d(up), 0.0);
down = d < 0;
t(down) = w(down) .* min(v - d(down), 0.0);
acc = sum(t);
end

function x = move(B, x, u)
x(@P@) = max(u - B(@R@), min(u + B(@R@), x(@P@)));
x(@Z@) = x(@Z@) + B(@C@) .* (u - x(@Z@));
end
{_M_INVERSE if plan.inverse else _M_FORWARD}"""
    for key, value in spans.items():
        code = code.replace(key, value)
    return code


_M_FORWARD = """
function [y, x] = model_step(B, x, u)
x = move(B, x, u);
v = sum([B(4); B(@WH@) .* x(@P@); B(@WK@) .* x(@Z@)]);
y = superposition(v, B(@D@), B(@WD@));
end
"""

# The plays from the last to the first: big_w = sum w minus the ones done, tail the sum of
# w_j p_j done (eq. 2.19)
_M_INVERSE = """
function [u_hat, x] = model_step(B, x, y)
w = B(@W@);
v = sum([superposition(y, B(@D@), B(@WD@)) - B(4); -(B(@WK@) .* (1.0 - B(@C@)) .* x(@Z@))]);
p = x(@N@:-1:1);
big_w = cumsum([sum(w); -w(@N@:-1:2)]);
tail = cumsum([0.0; w(@N@:-1:2) .* p(1:end - 1)]);
q = big_w .* p + tail;
u_hat = sum(B(@WINV@) .* max(v - B(@RINV@), min(v + B(@RINV@), q)));
x = move(B, x, u_hat);
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("move", "superposition"),
    extra=extra)
