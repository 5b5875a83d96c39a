"""The block in C99 and MATLAB, reading the body at the indices of ``kernels.py``."""

from hystkit.models import Translation

from .kernels import BIAS, DT, RATE, W0, W1


def c_model(plan, lit) -> str:
    rest = ("value" if not plan.inverse else
            f"(value - BODY[{BIAS}]) / (BODY[{W0}] + BODY[{W1}])")
    if plan.inverse:
        out, u = f"(u - BODY[{W1}] * x[0] - BODY[{BIAS}]) / BODY[{W0}]", "out"
    else:
        out, u = f"BODY[{W0}] * u + BODY[{W1}] * x[0] + BODY[{BIAS}]", "u"
    return f"""
static void model_rest(real *x, real value)
{{
    x[0] = {rest};
}}

static real model_step(real *x, real u)
{{
    const real out = {out};
    x[0] = x[0] + BODY[{RATE}] * BODY[{DT}] * ({u} - x[0]);
    return out;
}}
"""


def m_model(plan, lit) -> str:
    b = {name: index + 1 for name, index in
         (("rate", RATE), ("w0", W0), ("w1", W1), ("bias", BIAS), ("dt", DT))}
    rest = ("x = value;" if not plan.inverse else
            f"x = (value - B({b['bias']})) / (B({b['w0']}) + B({b['w1']}));")
    if plan.inverse:
        out, u = f"(u - B({b['w1']}) * x(1) - B({b['bias']})) / B({b['w0']})", "out"
    else:
        out, u = f"B({b['w0']}) * u + B({b['w1']}) * x(1) + B({b['bias']})", "u"
    return f"""function x = model_rest(B, value)
{rest}
end

function [out, x] = model_step(B, x, u)
out = {out};
x(1) = x(1) + B({b['rate']}) * B({b['dt']}) * ({u} - x(1));
end
"""


TRANSLATION = Translation(c_model=c_model, m_model=m_model)
