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

from .._cubic_output_code import C_FORWARD, C_INVERSE, C_SOLVE, M_CUBIC, M_SOLVE, m_step
from .._protocol import Translation
from .._translation import linear_readout_rest
from ..mpl.export import M_SINH_CURRENT, c_cells

_IC = 13  # body index of i_s (the C's IC, the MATLAB's ic)


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
{C_INVERSE if plan.inverse else C_FORWARD}"""



def m_model(plan, lit: Callable[[float], str]) -> str:
    w_sum = plan.extra["W_SUM"]
    n = int(plan.body[0])
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
v = drive - x;
i_s = B({_IC + 1}:{_IC + n}); v_t = B({_IC + n + 1}:{_IC + 2 * n});
knee = B({_IC + 2 * n + 1}:{_IC + 3 * n}); cap = B(3);
{M_SINH_CURRENT}x = x + f * B(4);
end

{M_SOLVE if plan.inverse else ""}{m_step(plan.inverse, 3)}"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("cells", "cubic", "solve_output"),
    extra=linear_readout_rest)
