"""mPL (``models/mpl/kernels.py``): ``block_forward`` / ``block_inverse`` and the rest state.

Body: ``[n, v_b, cap, dt, i_s (n), v_t (n), knee (n), w (n + 1)]``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._protocol import Translation
from .._translation import c_linear_readout, linear_readout_rest, m_linear_readout
from .cell_kernels import constants


def _cell_constants_c(plan, lit: Callable[[float], str], i_s_at: int) -> str:
    """The per-cell constants of ``kernels.cell_constants`` (1 / V_T, 2 I_S dt, the straight
    branch's offset c0) and cap dt, computed here by the kernel itself, so the exported step
    does per sample exactly what ``kernels.simulate`` does (bit for bit in double)."""
    n = int(plan.body[0])
    cap, dt = float(plan.body[2]), float(plan.body[3])
    i_s, v_t, knee = (np.ascontiguousarray(plan.body[i_s_at + j * n:i_s_at + (j + 1) * n])
                      for j in range(3))
    inv_vt, two_i_s_dt, c0 = constants(i_s, v_t, knee, cap, dt)
    rows = [("INV_VT", inv_vt), ("TWO_IS_DT", two_i_s_dt), ("C0", c0)]
    arrays = "".join(f"static const real {name}[N_CELLS] = {{{', '.join(lit(v) for v in vals)}}};\n"
                     for name, vals in rows)
    return arrays + f"#define CAP_DT {lit(cap * dt)}\n"


# sinh(a) below |a| = 0.5 (kernels.sinh_series): a (1 + a^2 / 3! + ... + a^14 / 15!), Estrin
_SERIES = (1.0 / 6.0, 1.0 / 120.0, 1.0 / 5040.0, 1.0 / 362880.0, 1.0 / 39916800.0,
           1.0 / 6227020800.0, 1.0 / 1307674368000.0)


def c_cells(plan, lit: Callable[[float], str], i_s_at: int) -> str:
    """C of the cells' update, ``static real cell_increment(real v, int k)`` (``f(v) dt`` of
    cell ``k``, ``kernels.cell_increment``) and the constants it reads, for any family whose
    body is ``[n, v_b, cap, dt, ...]`` with ``i_s (n), v_t (n), knee (n)`` from ``BODY[i_s_at]``
    on and ``N_CELLS`` defined: mPL and mpl-g advance their cells with this code."""
    c = [lit(v) for v in _SERIES]
    return f"""/* Per cell, fixed at export (kernels.cell_constants): 1 / V_T, 2 I_S dt and c0 = (f(knee) -
 * cap knee) dt, the straight branch beyond the knee being f dt = s c0 + cap dt v. */
{_cell_constants_c(plan, lit, i_s_at)}
/* sinh(a) from one exp (kernels.sinh_cosh): (e - 1/e) / 2, and below |a| = 0.5, where that
 * cancels, the series a (1 + a^2 / 3! + ... + a^14 / 15!) (kernels.sinh_series) */
static real sinh_one_exp(real a)
{{
    const real t = FABS(a);
    const real e = EXP(t);
    const real e_inv = R(1.0) / e;
    const real a2 = a * a;
    const real a4 = a2 * a2;
    const real a8 = a4 * a4;
    const real p01 = R(1.0) + a2 * {c[0]};
    const real p23 = {c[1]} + a2 * {c[2]};
    const real p45 = {c[3]} + a2 * {c[4]};
    const real p67 = {c[5]} + a2 * {c[6]};
    const real half = R(0.5) * (e - e_inv);
    if (t < R(0.5)) return a * ((p01 + a4 * p23) + a8 * (p45 + a4 * p67));
    return a < R(0.0) ? -half : half;  /* copysign: a is not 0 here */
}}

/* f(v) dt of the limited sinh resistor (eq. 5.1 with eq. 5.29): kernels.cell_increment */
static real cell_increment(real v, int k)
{{
    const real knee = BODY[{i_s_at} + 2 * N_CELLS + k];
    if (FABS(v) <= knee) return TWO_IS_DT[k] * sinh_one_exp(v * INV_VT[k]);
    return (v > R(0.0) ? C0[k] : -C0[k]) + CAP_DT * v;
}}
"""


def c_model(plan, lit: Callable[[float], str]) -> str:
    n = int(plan.body[0])
    w_sum = plan.extra["W_SUM"]
    rest = ("x[k] = value;" if not plan.inverse else  # mpl.invert's start
            f"x[k] = (value + BODY[1]) / {lit(w_sum)};" if w_sum != 0 else "x[k] = R(0.0);")
    out = "drive" if plan.inverse else "acc"
    return f"""#define N_CELLS {n}
#define IW (4 + 3 * N_CELLS)

{c_cells(plan, lit, 4)}
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
{c_linear_readout(plan.inverse)}
    for (k = 0; k < N_CELLS; k++) x[k] = x[k] + cell_increment(drive - x[k], k);
    return {out};
}}
"""


# The limited sinh resistor (eq. 5.1 with eq. 5.29) in MATLAB: f of every cell at once (column
# vectors v, i_s, v_t, knee; cap a number), each cell's arithmetic the C's (mpl-g's cells use it
# too). Octave interprets each statement and call: array operations, not a call per cell.
M_SINH_CURRENT = """f = 2.0 * i_s .* sinh(v ./ v_t);
far = ~(abs(v) <= knee);
if any(far)
    s = 2.0 * (v(far) > 0) - 1.0;
    f(far) = s .* 2.0 .* i_s(far) .* sinh(knee(far) ./ v_t(far)) + cap * (v(far) - s .* knee(far));
end
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    w_sum = plan.extra["W_SUM"]
    n = int(plan.body[0])
    rest = ("v = value;" if not plan.inverse else
            f"v = (value + B(2)) / {lit(w_sum)};" if w_sum != 0 else "v = 0.0;")
    return f"""function x = model_rest(B, value)
{rest}
x = v * ones(round(B(1)), 1);
end

function [out, x] = model_step(B, x, u)
n = round(B(1));
iw = 5 + 3 * n;
{m_linear_readout(plan.inverse)}
x = x + mpl_current(drive - x, B(5:{4 + n}), B({5 + n}:{4 + 2 * n}), B({5 + 2 * n}:{4 + 3 * n}), ...
                    B(3)) * B(4);
end

function f = mpl_current(v, i_s, v_t, knee, cap)
{M_SINH_CURRENT}end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("mpl_current",),
    extra=linear_readout_rest)
