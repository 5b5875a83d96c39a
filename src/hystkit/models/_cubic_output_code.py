"""The cubic output resistor ``g`` and its inverse on the rest branch (``solve_output``) in C
and MATLAB, shared by the mpl-poly and mpl-g translations (``<family>/export.py``), as their
kernels share ``mpl_poly.kernels.solve_output``: both bodies start with the same head
``[n, v_b, cap, dt, limit, lo, hi, sign, centre, g0..g3, ...]``.

Plain text, no format fields; the C needs ``cubic(g, z, &slope)``, ``IG``, ``IW``, ``N_CELLS``,
``cells(x, drive)`` and ``BODY`` from the family's code, the MATLAB ``cells(B, x, drive)``. The
block's step reads the output through ``g`` from ``z = w_0 u + sum w_k x_k - V_b`` (forward) or
solves it for ``z`` and then ``u`` (inverse), then drives the cells: the same in both families
but for how many body values each cell takes (:func:`m_step`).
"""

C_SOLVE = """
/* The z on the rest branch [lo, hi] of g with g(z) = i: safeguarded Newton inside a
   bisection bracket (kernels.solve_output); *ok = 0 when i is outside the branch's range */
static real solve_output(real i, int *ok)
{
    const real *g = BODY + IG;
    const real lo = BODY[5], hi = BODY[6], sign = BODY[7], centre = BODY[8];
    real width = R(1.0), a, b, h_a, h_b, z;
    int it;
    *ok = 0;
    a = isfinite(lo) ? lo : centre - width;
    h_a = sign * (cubic(g, a, 0) - i);
    while (h_a > R(0.0)) {
        if (isfinite(lo) || width > R(1e15)) return R(0.0);
        width *= R(2.0);
        a = centre - width;
        h_a = sign * (cubic(g, a, 0) - i);
    }
    width = R(1.0);
    b = isfinite(hi) ? hi : centre + width;
    h_b = sign * (cubic(g, b, 0) - i);
    while (h_b < R(0.0)) {
        if (isfinite(hi) || width > R(1e15)) return R(0.0);
        width *= R(2.0);
        b = centre + width;
        h_b = sign * (cubic(g, b, 0) - i);
    }
    z = g[1] != R(0.0) ? (i - g[0]) / g[1] : a;
    if (!(a < z && z < b)) z = R(0.5) * (a + b);
    for (it = 0; it < 200; it++) {
        real dg, gz = cubic(g, z, &dg), h, z_new;
        int newton;
        h = sign * (gz - i);
        if (h == R(0.0)) break;
        if (h < R(0.0)) a = z;
        else b = z;
        newton = dg != R(0.0);
        z_new = newton ? z - (gz - i) / dg : z;
        if (!newton || !(a < z_new && z_new < b)) z_new = R(0.5) * (a + b);
        if (FABS(z_new - z) <= R(4e-16) * (R(1.0) + FABS(z))
            || b - a <= R(4e-16) * (R(1.0) + FABS(z))) {
            z = z_new;
            break;
        }
        z = z_new;
    }
    *ok = 1;
    return z;
}
"""

M_CUBIC = """function [v, slope] = cubic(c, x)
v = c(1) + x * (c(2) + x * (c(3) + x * c(4)));
slope = c(2) + x * (2.0 * c(3) + 3.0 * c(4) * x);
end

"""

# cubic(g, z) written out as g0 + z (g1 + z (g2 + z g3)): a call per Newton step costs more than
# the arithmetic in Octave, which interprets each one
M_SOLVE = """function [z, ok] = solve_output(B, i)
g0 = B(10); g1 = B(11); g2 = B(12); g3 = B(13);
lo = B(6); hi = B(7); sign_ = B(8); centre = B(9);
z = NaN; ok = false;
width = 1.0;
if isfinite(lo), a = lo; else, a = centre - width; end
h_a = sign_ * ((g0 + a * (g1 + a * (g2 + a * g3))) - i);
while h_a > 0
    if isfinite(lo) || width > 1e15, return; end
    width = width * 2.0;
    a = centre - width;
    h_a = sign_ * ((g0 + a * (g1 + a * (g2 + a * g3))) - i);
end
width = 1.0;
if isfinite(hi), b = hi; else, b = centre + width; end
h_b = sign_ * ((g0 + b * (g1 + b * (g2 + b * g3))) - i);
while h_b < 0
    if isfinite(hi) || width > 1e15, return; end
    width = width * 2.0;
    b = centre + width;
    h_b = sign_ * ((g0 + b * (g1 + b * (g2 + b * g3))) - i);
end
if g1 ~= 0, z = (i - g0) / g1; else, z = NaN; end
if ~(a < z && z < b), z = 0.5 * (a + b); end
g2_2 = 2.0 * g2; g3_3 = 3.0 * g3;
for it = 1:200
    r = (g0 + z * (g1 + z * (g2 + z * g3))) - i;
    dg = g1 + z * (g2_2 + g3_3 * z);
    h = sign_ * r;
    if h == 0, break; end
    if h < 0, a = z; else, b = z; end
    z_new = z - r / dg;  % dg = 0 gives +-Inf (r is not 0): outside (a, b), as NaN would be
    if ~(a < z_new && z_new < b), z_new = 0.5 * (a + b); end
    near = 4e-16 * (1.0 + abs(z));
    if abs(z_new - z) <= near || b - a <= near
        z = z_new;
        break;
    end
    z = z_new;
end
ok = true;
end
"""


C_FORWARD = """
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

C_INVERSE = """
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

_M_FORWARD = """
function [y, x] = model_step(B, x, u)
n = round(B(1)); iw = 14 + @PER_CELL@ * n;
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
n = round(B(1)); iw = 14 + @PER_CELL@ * n;
[z, ok] = solve_output(B, y);
acc = z + B(2);
for k = 1:n
    acc = acc - B(iw + k) * x(k);
end
if ok, u_hat = acc / B(iw); else, u_hat = NaN; end
x = cells(B, x, u_hat);
end
"""


def m_step(inverse: bool, per_cell: int) -> str:
    """The MATLAB ``model_step`` of a body with `per_cell` values per cell before ``w``."""
    return (_M_INVERSE if inverse else _M_FORWARD).replace("@PER_CELL@", str(per_cell))
