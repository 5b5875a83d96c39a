"""PWL ladder (``models/ladder/kernels.py``): ``block_forward`` / ``block_inverse``, rest state.

Body: ``[N, V_b, dt, band (N), effective conductance (N), w (N + 1)]``.
"""

from __future__ import annotations

from collections.abc import Callable

from .._protocol import Translation
from .._translation import c_linear_readout, linear_readout_rest, m_linear_readout


def c_model(plan, lit: Callable[[float], str]) -> str:
    n = int(plan.body[0])
    w_sum = plan.extra["W_SUM"]
    rest = ("value" if not plan.inverse else
            f"(value + BODY[1]) / {lit(w_sum)}" if w_sum != 0 else "R(0.0)")
    head = c_linear_readout(plan.inverse) + f"\n    out = {'drive' if plan.inverse else 'acc'};"
    return f"""#define N_CELLS {n}
#define IW (3 + 2 * N_CELLS)

/* Dead-zone resistor current (kernels._dead_zone_current) */
static real dead_zone(real v, int k)
{{
    const real band = BODY[3 + k], g = BODY[3 + N_CELLS + k];
    if (v > band) return g * (v - band);
    if (v < -band) return g * (v + band);
    return R(0.0);
}}

static void model_rest(real *x, real value)
{{
    int k;
    const real v = {rest};
    for (k = 0; k < N_CELLS; k++) x[k] = v;
}}

/* Output from the present voltages, then the Euler step (kernels.euler) driven by the source */
static real model_step(real *x, real u)
{{
    int k;
    real drive, out, i_in, i_out;
{head}
    i_in = dead_zone(drive - x[0], 0);
    for (k = 0; k < N_CELLS; k++) {{
        i_out = R(0.0);
        if (k + 1 < N_CELLS) i_out = dead_zone(x[k] - x[k + 1], k + 1);
        x[k] = x[k] + BODY[2] * (i_in - i_out);
        i_in = i_out;
    }}
    return out;
}}
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    w_sum = plan.extra["W_SUM"]
    n = int(plan.body[0])
    rest = ("value" if not plan.inverse else
            f"(value + B(2)) / {lit(w_sum)}" if w_sum != 0 else "0.0")
    # every dead zone at once (Octave interprets each call): zone 1 between the drive and
    # cell 1, zone k + 1 between cells k and k + 1, all from the states before the step
    return f"""function x = model_rest(B, value)
x = ({rest}) * ones(round(B(1)), 1);
end

function [out, x] = model_step(B, x, u)
n = round(B(1));
iw = 4 + 2 * n;
{m_linear_readout(plan.inverse)}
i = dead_zone([drive - x(1); x(1:{n - 1}) - x(2:{n})], B(4:{3 + n}), B({4 + n}:{3 + 2 * n}));
x = x + B(3) * (i - [i(2:{n}); 0.0]);
end

function i = dead_zone(v, band, g)
i = zeros(size(v));
up = v > band;
i(up) = g(up) .* (v(up) - band(up));
down = ~up & v < -band;
i(down) = g(down) .* (v(down) + band(down));
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("dead_zone",),
    extra=linear_readout_rest)
