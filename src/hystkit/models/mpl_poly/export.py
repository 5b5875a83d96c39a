"""Polynomial mPL (``models/mpl_poly/kernels.py``): ``block_forward`` / ``block_inverse``
(``solve_output`` on the rest branch of ``g``) and the rest state (``model.rest_state``).

Body: ``[n, v_b, s, dt, limit, lo, hi, sign, centre, g0..g3, fc (N x 4), knees (N x 2),
w (N + 1)]``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._cubic_output_code import C_FORWARD, C_INVERSE, C_SOLVE, M_CUBIC, M_SOLVE, m_step
from .._protocol import Translation
from .rest import rest_voltages


def extra(comp) -> dict:
    """Rest voltages ``v*_k`` (the forward rest is ``e - v*``), ``sum(w)`` and ``w . v*`` of
    the inverse's rest input (``model.rest_state``)."""
    p = comp.params
    v_rest = np.asarray(rest_voltages(comp.structure, p), float)
    return {"V_REST": v_rest, "W_SUM": float(p.w.sum()), "W_V": float(p.w[1:] @ v_rest)}


def c_model(plan, lit: Callable[[float], str]) -> str:
    n = int(plan.body[0])
    e = plan.extra
    v_rest = ", ".join(lit(v) for v in e["V_REST"])
    if not plan.inverse:
        rest_e = "value"
    elif e["W_SUM"] != 0:
        rest_e = (f"ok ? (z0 + {lit(e['W_V'])} + BODY[1]) / {lit(e['W_SUM'])} : R(0.0)")
    else:
        rest_e = "R(0.0)"
    rest_z = ("    int ok;\n    const real z0 = solve_output(value, &ok);\n"
              if plan.inverse and e["W_SUM"] != 0 else
              "    (void)value;\n" if plan.inverse else "")
    step = C_INVERSE if plan.inverse else C_FORWARD
    solver = C_SOLVE if plan.inverse else ""
    return f"""#define N_CELLS {n}
#define IG 9
#define IF 13
#define IK (IF + 4 * N_CELLS)
#define IW (IF + 6 * N_CELLS)

static const real V_REST[N_CELLS] = {{{v_rest}}};

/* c0 + c1 x + c2 x^2 + c3 x^3 and its slope: kernels._cubic */
static real cubic(const real *c, real x, real *slope)
{{
    if (slope != 0) *slope = c[1] + x * (R(2.0) * c[2] + R(3.0) * c[3] * x);
    return c[0] + x * (c[1] + x * (c[2] + x * c[3]));
}}

/* Limited cell-resistor current (eq. 5.16, 5.29): kernels._cell */
static real cell(real v, int k)
{{
    const real xm = BODY[IK + 2 * k], xp = BODY[IK + 2 * k + 1];
    if (BODY[4] != R(0.0) && (v >= xp || v <= xm)) {{
        const real x_b = v >= xp ? xp : xm;
        return cubic(BODY + IF + 4 * k, x_b, 0) + BODY[2] * (v - x_b);
    }}
    return cubic(BODY + IF + 4 * k, v, 0);
}}

static void cells(real *x, real drive)
{{
    int k;
    for (k = 0; k < N_CELLS; k++) x[k] = x[k] + cell(drive - x[k], k) * BODY[3];
}}
{solver}
static void model_rest(real *x, real value)
{{
    int k;
{rest_z}    {{
        const real e0 = {rest_e};
        for (k = 0; k < N_CELLS; k++) x[k] = e0 - V_REST[k];
    }}
}}
{step}"""



def m_model(plan, lit: Callable[[float], str]) -> str:
    e = plan.extra
    v_rest = "[" + "; ".join(lit(v) for v in e["V_REST"]) + "]"
    if not plan.inverse:
        rest = "e0 = value;"
    elif e["W_SUM"] != 0:
        rest = (f"[z0, ok] = solve_output(B, value);\nif ok\n    e0 = (z0 + {lit(e['W_V'])} "
                f"+ B(2)) / {lit(e['W_SUM'])};\nelse\n    e0 = 0.0;\nend")
    else:
        rest = "e0 = 0.0;"
    step = m_step(plan.inverse, 6)
    return f"""function x = model_rest(B, value)
{rest}
x = e0 - {v_rest};
end

{M_CUBIC}function x = cells(B, x, drive)
n = round(B(1)); if_ = 13; ik = if_ + 4 * n;
for k = 1:n
    v = drive - x(k);
    c = B(if_ + 4 * (k - 1) + 1:if_ + 4 * k);
    xm = B(ik + 2 * k - 1); xp = B(ik + 2 * k);
    if B(5) ~= 0 && (v >= xp || v <= xm)
        if v >= xp, x_b = xp; else, x_b = xm; end
        f = cubic(c, x_b) + B(3) * (v - x_b);
    else
        f = cubic(c, v);
    end
    x(k) = x(k) + f * B(4);
end
end

{M_SOLVE}{step}"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("cells", "cubic", "solve_output"),
    extra=extra)
