"""Bouc-Wen oscillator (``models/boucwen/kernels.py``): ``block_forward`` (RK4 substeps from the
previous force sample to this one) and the start state (``model.initial_state``); no inverse.

Body: ``[m, c, k, alpha, beta, gamma, nu, dt, substeps, linear]``; state ``(y, v, z, u_prev)``.
"""

from __future__ import annotations

from collections.abc import Callable
from textwrap import indent

from .._protocol import Translation


def extra(comp) -> dict:
    """The start: ``rest`` (``y = z = 0``) or ``equilibrium`` (``y = u / K0``,
    ``z = alpha y``)."""
    s, p = comp.structure, comp.params
    return {"EQUILIBRIUM": s.start != "rest", "K0": float(p.k0), "ALPHA": float(p.alpha)}


def c_model(plan, lit: Callable[[float], str]) -> str:
    e = plan.extra
    rest = (f"const real y0 = value / {lit(e['K0'])};\n    x[0] = y0;\n    x[1] = R(0.0);\n"
            f"    x[2] = {lit(e['ALPHA'])} * y0;" if e["EQUILIBRIUM"] else
            "x[0] = R(0.0);\n    x[1] = R(0.0);\n    x[2] = R(0.0);")
    return f"""/* Right-hand side (dy/dt, dv/dt, dz/dt) with the Bouc-Wen force z: kernels._rhs */
static void rhs(real y, real v, real z, real u, real *dy, real *dv, real *dz)
{{
    const real m = BODY[0], c = BODY[1], k = BODY[2], alpha = BODY[3], beta = BODY[4];
    const real gamma = BODY[5], nu = BODY[6];
    const real p = nu == R(1.0) ? FABS(z) : EXP(nu * LOG(FABS(z)));
    const real q = z >= R(0.0) ? p : -p;
    *dz = alpha * v - beta * FABS(v) * q - gamma * v * p;
    *dy = v;
    *dv = (u - c * v - k * y - z) * (R(1.0) / m);  /* as the kernel: times 1 / m */
}}

static void model_rest(real *x, real value)
{{
    {rest}
    x[3] = value;
}}

/* block_forward: RK4 substeps from the previous force sample to u (kernels.advance) */
static real model_step(real *x, real u)
{{
    const int n_sub = (int)BODY[8];
    const real h = BODY[7] / (real)n_sub, u_a = x[3];
    const real du = BODY[9] != R(0.0) ? (u - u_a) / (real)n_sub : R(0.0);
    real y = x[0], v = x[1], z = x[2];
    int j;
    for (j = 0; j < n_sub; j++) {{
        const real u0 = u_a + (real)j * du, u1 = u0 + R(0.5) * du, u2 = u0 + du;
        real k1y, k1v, k1z, k2y, k2v, k2z, k3y, k3v, k3z, k4y, k4v, k4z;
        rhs(y, v, z, u0, &k1y, &k1v, &k1z);
        rhs(y + R(0.5) * h * k1y, v + R(0.5) * h * k1v, z + R(0.5) * h * k1z, u1,
            &k2y, &k2v, &k2z);
        rhs(y + R(0.5) * h * k2y, v + R(0.5) * h * k2v, z + R(0.5) * h * k2z, u1,
            &k3y, &k3v, &k3z);
        rhs(y + h * k3y, v + h * k3v, z + h * k3z, u2, &k4y, &k4v, &k4z);
        y += h / R(6.0) * (k1y + R(2.0) * k2y + R(2.0) * k3y + k4y);
        v += h / R(6.0) * (k1v + R(2.0) * k2v + R(2.0) * k3v + k4v);
        z += h / R(6.0) * (k1z + R(2.0) * k2z + R(2.0) * k3z + k4z);
    }}
    x[0] = y;
    x[1] = v;
    x[2] = z;
    x[3] = u;
    return y;
}}
"""


def _m_rhs(k: int, y: str, v: str, z: str, u: str) -> str:
    """The Bouc-Wen right-hand side at (y, v, z, u) into kKy, kKv, kKz (the kernel's ``rhs``,
    written out: Octave would spend more on the call than on the arithmetic)."""
    return f"""yy = {y}; vv = {v}; zz = {z};
if nu == 1.0, p = abs(zz); else, p = exp(nu * log(abs(zz))); end
if zz >= 0.0, q = p; else, q = -p; end
k{k}z = alpha * vv - beta * abs(vv) * q - gamma * vv * p;
k{k}y = vv;
k{k}v = ({u} - c * vv - k_ * yy - zz) * (1.0 / m);  % as the kernel: times 1 / m
"""


def m_model(plan, lit: Callable[[float], str]) -> str:
    e = plan.extra
    rest = (f"y0 = value / {lit(e['K0'])};\nx = [y0; 0.0; {lit(e['ALPHA'])} * y0; value];"
            if e["EQUILIBRIUM"] else "x = [0.0; 0.0; 0.0; value];")
    stages = (_m_rhs(1, "y", "v", "z", "u0")
              + _m_rhs(2, "y + 0.5 * h * k1y", "v + 0.5 * h * k1v", "z + 0.5 * h * k1z", "u1")
              + _m_rhs(3, "y + 0.5 * h * k2y", "v + 0.5 * h * k2v", "z + 0.5 * h * k2z", "u1")
              + _m_rhs(4, "y + h * k3y", "v + h * k3v", "z + h * k3z", "u2"))
    return f"""function x = model_rest(B, value)
{rest}
end

function [out, x] = model_step(B, x, u)
m = B(1); c = B(2); k_ = B(3); alpha = B(4); beta = B(5); gamma = B(6); nu = B(7);
n_sub = fix(B(9));
h = B(8) / n_sub; u_a = x(4);
if B(10) ~= 0, du = (u - u_a) / n_sub; else, du = 0.0; end
y = x(1); v = x(2); z = x(3);
for j = 0:n_sub - 1
    u0 = u_a + j * du; u1 = u0 + 0.5 * du; u2 = u0 + du;
{indent(stages, "    ")}    y = y + h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
    v = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    z = z + h / 6.0 * (k1z + 2.0 * k2z + 2.0 * k3z + k4z);
end
x = [y; v; z; u];
out = y;
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    extra=extra,
    inverse=False)
