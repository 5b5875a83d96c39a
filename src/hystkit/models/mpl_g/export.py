"""The ch. 7 compensator (``models/mpl_g/kernels.py``): ``block_forward`` / ``block_inverse``
and the rest state (``model.rest_state``). The sinh cells are the mPL's exported code
(``mpl.export.c_cells``: per-cell constants fixed at export, one exp per cell, bit for bit
``mpl.kernels.cell_increment`` in double), the inverse of the cubic output resistor is the
mpl-poly's (``solve_output``, same body head).

Body: ``[n, v_b, cap, dt, 1, lo, hi, sign, centre, g0..g3, i_s (n), v_t (n), knee (n),
w (n + 1)]``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._cubic_output_code import C_SOLVE, M_CUBIC, M_SOLVE
from .._protocol import Translation
from ..mpl.export import c_cells

_IC = 13  # body index of i_s (the C's IC, the MATLAB's ic)


def extra(comp) -> dict:
    """``W_SUM``: ``sum(w)``, the divisor of the inverse's rest input ``(z_0 + V_b) / sum(w)``."""
    return {"W_SUM": float(np.sum(comp.params.w))}


def c_model(plan, lit: Callable[[float], str]) -> str:
    n = int(plan.body[0])
    w_sum = plan.extra["W_SUM"]
    if not plan.inverse:
        rest = "    const real e0 = value;\n"
    elif w_sum != 0:
        rest = ("    int ok;\n    const real z0 = solve_output(value, &ok);\n"
                f"    const real e0 = ok ? (z0 + BODY[1]) / {lit(w_sum)} : R(0.0);\n")
    else:
        rest = "    const real e0 = R(0.0);\n    (void)value;\n"
    return f"""#define N_CELLS {n}
#define IG 9
#define IC {_IC}
#define IW (IC + 3 * N_CELLS)

/* g0 + g1 z + g2 z^2 + g3 z^3 and its slope (eq. 5.16-5.17): kernels._output */
static real cubic(const real *c, real x, real *slope)
{{
    if (slope != 0) *slope = c[1] + x * (R(2.0) * c[2] + R(3.0) * c[3] * x);
    return c[0] + x * (c[1] + x * (c[2] + x * c[3]));
}}

{c_cells(plan, lit, _IC)}
/* the cells driven by drive (eq. 5.6), as kernels.simulate / invert advance them */
static void cells(real *x, real drive)
{{
    int k;
    for (k = 0; k < N_CELLS; k++) x[k] = x[k] + cell_increment(drive - x[k], k);
}}
{C_SOLVE if plan.inverse else ""}
static void model_rest(real *x, real value)
{{
    int k;
{rest}    for (k = 0; k < N_CELLS; k++) x[k] = e0;
}}
{_C_INVERSE if plan.inverse else _C_FORWARD}"""


_C_FORWARD = """
/* block_forward: y = g(w_0 u + sum w_k x_k - V_b) (eq. 5.17), then the cells driven by u */
static real model_step(real *x, real u)
{
    int k;
    real z = BODY[IW] * u - BODY[1], y;
    for (k = 0; k < N_CELLS; k++) z += BODY[IW + 1 + k] * x[k];
    y = cubic(BODY + IG, z, 0);
    cells(x, u);
    return y;
}
"""

_C_INVERSE = """
/* block_inverse: z = g^-1(y) on the rest branch, u_hat = (z - sum w_k x_k + V_b) / w_0, the
   cells driven by u_hat; NaN when y is outside the branch's range (no input gives it) */
static real model_step(real *x, real y)
{
    int k, ok;
    const real z = solve_output(y, &ok);
    real acc = z + BODY[1], u_hat;
    for (k = 0; k < N_CELLS; k++) acc -= BODY[IW + 1 + k] * x[k];
    u_hat = ok ? acc / BODY[IW] : (real)NAN;
    cells(x, u_hat);
    return u_hat;
}
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    w_sum = plan.extra["W_SUM"]
    if not plan.inverse:
        rest = "e0 = value;"
    elif w_sum != 0:
        rest = (f"[z0, ok] = solve_output(B, value);\nif ok\n    e0 = (z0 + B(2)) / "
                f"{lit(w_sum)};\nelse\n    e0 = 0.0;\nend")
    else:
        rest = "e0 = 0.0;"
    return f"""function x = model_rest(B, value)
{rest}
x = e0 * ones(round(B(1)), 1);
end

{M_CUBIC}function x = cells(B, x, drive)
n = round(B(1)); ic = 13;
for k = 1:n
    v = drive - x(k);
    i_s = B(ic + k); v_t = B(ic + n + k); knee = B(ic + 2 * n + k); cap = B(3);
    if abs(v) <= knee
        f = 2.0 * i_s * sinh(v / v_t);
    else
        s = -1.0; if v > 0, s = 1.0; end
        f = s * 2.0 * i_s * sinh(knee / v_t) + cap * (v - s * knee);
    end
    x(k) = x(k) + f * B(4);
end
end

{M_SOLVE if plan.inverse else ""}{_M_INVERSE if plan.inverse else _M_FORWARD}"""


_M_FORWARD = """
function [y, x] = model_step(B, x, u)
n = round(B(1)); iw = 14 + 3 * n;
z = B(iw) * u - B(2);
for k = 1:n
    z = z + B(iw + k) * x(k);
end
y = cubic(B(10:13), z);
x = cells(B, x, u);
end
"""

_M_INVERSE = """
function [u_hat, x] = model_step(B, x, y)
n = round(B(1)); iw = 14 + 3 * n;
[z, ok] = solve_output(B, y);
acc = z + B(2);
for k = 1:n
    acc = acc - B(iw + k) * x(k);
end
if ok, u_hat = acc / B(iw); else, u_hat = NaN; end
x = cells(B, x, u_hat);
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("cells", "cubic", "solve_output"),
    extra=extra)
