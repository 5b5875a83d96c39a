"""The staircase block in C99 (:func:`c_model`), for :mod:`.export`: the forward step and the
inverse's bisection on the branch, with the running sums the run kernels keep.
"""

from __future__ import annotations

from collections.abc import Callable

from .export_layout import FLOAT_TOL, REST_TOL, body_sizes

__all__ = ["c_model"]


def c_model(plan, lit: Callable[[float], str]) -> str:
    cap, levels, n_tab, n_poly = body_sizes(plan)
    double = not lit(0.5).endswith("f")  # the literal formatter says which precision
    tol = "BODY[5]" if double else f"max2(BODY[5], {lit(FLOAT_TOL)})"
    demag = ", ".join(lit(v) for v in plan.extra["DEMAG"])
    step = (_C_INVERSE if plan.inverse else _C_FORWARD).replace("@TOL@", tol)
    return f"""#define CAP {cap}
#define LEV {levels}
#define NTAB {n_tab}
#define N_POLY {n_poly}
#define I_A (7 + N_POLY)
#define REST_TOL {lit(REST_TOL if double else FLOAT_TOL)}
#define A(k, i, j) BODY[I_A + ((k) * LEV + (i)) * LEV + (j)]
#define S(x) ((x) + 1)              /* the staircase s_0 .. s_{{CAP-1}} */
#define C(x, i, k) (x)[1 + CAP + (i) * NTAB + (k)]  /* running sums */

static const real DEMAG[{plan.extra['DEMAG'].size}] = {{{demag}}};

static real max2(real a, real b) {{ return b > a ? b : a; }}
static real min2(real a, real b) {{ return b < a ? b : a; }}

/* Bilinearly interpolated F_k(a, b), -1 <= b <= a <= 1: kernels._everett */
static real everett(int k, real a, real b)
{{
    const real scale = R(0.5) * (real)(LEV - 1);
    const real xa = (a + R(1.0)) * scale, xb = (b + R(1.0)) * scale;
    int ia = (int)xa, ib = (int)xb;
    real sa, sb;
    if (ia > LEV - 2) ia = LEV - 2;
    if (ib > LEV - 2) ib = LEV - 2;
    sa = xa - (real)ia;
    sb = xb - (real)ib;
    return ((R(1.0) - sa) * ((R(1.0) - sb) * A(k, ia, ib) + sb * A(k, ia, ib + 1))
            + sa * ((R(1.0) - sb) * A(k, ia + 1, ib) + sb * A(k, ia + 1, ib + 1)));
}}

/* Segment term of eq. 9.13 for the input moving from p to q: kernels._term */
static real term(int k, real p, real q)
{{
    if (q >= p) return everett(k, q, p);
    return -everett(k, p, q);
}}

static int length(const real *x) {{ return (int)(x[0] + R(0.5)); }}

/* Running sums of the closed segments of the staircase: kernels._sums */
static void load_sums(real *x)
{{
    const int n = length(x);
    int i, k;
    for (k = 0; k < NTAB; k++) C(x, 0, k) = R(0.0);
    for (i = 1; i < n - 1; i++)
        for (k = 0; k < NTAB; k++)
            C(x, i, k) = C(x, i - 1, k) + term(k, S(x)[i - 1], S(x)[i]);
}}

/* Before a sample: forget the innermost closed loop if a push could fill the buffer */
static int make_room(real *s, int n)
{{
    if (n >= CAP - 1) {{
        s[n - 3] = s[n - 1];
        n -= 2;
    }}
    return n;
}}

/* The staircase rule for the clipped input u (wiping-out): kernels._move */
static int move_to(real *s, int n, real u)
{{
    const real last = s[n - 1];
    if (u == last) return n;
    if (n == 1) {{
        s[1] = u;
        n = 2;
    }} else if ((u > last) == (last > s[n - 2])) {{
        s[n - 1] = u;
    }} else {{
        s[n] = u;
        n += 1;
    }}
    while (n >= 3) {{
        const int rising = s[n - 1] > s[n - 2];
        if ((rising && s[n - 1] >= s[n - 3]) || (!rising && s[n - 1] <= s[n - 3])) {{
            s[n - 3] = s[n - 1];
            n -= 2;
        }} else {{
            break;
        }}
    }}
    return n;
}}

/* move_to keeping the running sums: kernels._update */
static int update(real *x, int n, real u)
{{
    real *s = S(x);
    int k;
    if (n > 1 && u != s[n - 1] && (u > s[n - 1]) != (s[n - 1] > s[n - 2]))
        for (k = 0; k < NTAB; k++)
            C(x, n - 1, k) = C(x, n - 2, k) + term(k, s[n - 2], s[n - 1]);
    return move_to(s, n, u);
}}

/* Relay parts and reversible polynomial at the clipped input (eq. 2.2 / 9.13): combine */
static real combine(const real *p, real u)
{{
    real y, r = R(0.0);
    int i;
    if (BODY[3] != R(0.0)) {{
        const real w = R(0.5) * (R(1.0) + u);
        y = (R(1.0) - w) * p[0] + w * p[NTAB > 1 ? 1 : 0];
    }} else {{
        y = p[0];
    }}
    for (i = N_POLY - 1; i >= 0; i--) r = r * u + BODY[7 + i];
    return y + r;
}}

static real model_step(real *x, real u);

static void model_rest(real *x, real value)
{{
    int i;
    for (i = 0; i < CAP + 1 + CAP * NTAB; i++) x[i] = R(0.0);
    for (i = 0; i < {plan.extra['DEMAG'].size}; i++) S(x)[i] = DEMAG[i];
    x[0] = (real){plan.extra['DEMAG'].size};
    load_sums(x);
    (void)model_step(x, value);  /* the first sample from demagnetised: rest_state */
}}
{step}"""


_C_FORWARD = """
/* block_forward: staircase updated with the clipped u, then eq. 9.13 / eq. 2.2 and the
   straight line beyond [-1, 1] */
static real model_step(real *x, real u)
{
    const real u_clip = min2(R(1.0), max2(R(-1.0), u));
    real acc[NTAB];
    int n = length(x), k;
    n = make_room(S(x), n);
    n = update(x, n, u_clip);
    for (k = 0; k < NTAB; k++) {
        acc[k] = -A(k, LEV - 1, 0);
        if (n > 1)
            acc[k] = -A(k, LEV - 1, 0) + R(2.0) * (C(x, n - 2, k)
                                                   + term(k, S(x)[n - 2], S(x)[n - 1]));
    }
    x[0] = (real)n;
    return combine(acc, u_clip) + BODY[4] * (u - u_clip);
}
"""

_C_INVERSE = """
/* Largest j in start, start + 2, ... <= stop with s[j] > u (above) or s[j] < u; -1 if none:
   kernels._last_index (binary search: the qualifying indices form a prefix) */
static int last_index(const real *s, int start, int stop, real u, int above)
{
    int lo = 0, hi, found = -1;
    if (stop < start) return -1;
    hi = (stop - start) / 2;
    while (lo <= hi) {
        const int mid = (lo + hi) / 2, j = start + 2 * mid;
        if (above ? s[j] > u : s[j] < u) {
            found = j;
            lo = mid + 1;
        } else {
            hi = mid - 1;
        }
    }
    return found;
}

static real running_sum(const real *x, int n, int i, int k)
{
    if (i <= n - 2) return C(x, i, k);
    return C(x, n - 2, k) + term(k, S(x)[n - 2], S(x)[n - 1]);
}

/* Model output if the input moved straight to u in [-1, 1]: kernels._branch_output */
static real branch_output(real u, const real *x, int n)
{
    const real *s = S(x);
    real acc[NTAB];
    int i, k;
    if (u >= s[n - 1]) {
        i = last_index(s, 1, n - 2, u, 1) + 1;
        for (k = 0; k < NTAB; k++) {
            const real base = i > 0 ? running_sum(x, n, i, k) : R(0.0);
            acc[k] = -A(k, LEV - 1, 0) + R(2.0) * (base + everett(k, u, s[i]));
        }
    } else {
        i = last_index(s, 0, n - 2, u, 0);
        for (k = 0; k < NTAB; k++) {
            if (i < 0) acc[k] = -A(k, LEV - 1, 0);
            else acc[k] = -A(k, LEV - 1, 0) + R(2.0) * (running_sum(x, n, i + 1, k)
                                                         - everett(k, s[i + 1], u));
        }
    }
    return combine(acc, u);
}

/* One sample of the inverse: bisection on the branch, then the staircase updated with the
   estimate (kernels._invert_sample) */
static real model_step(real *x, real target)
{
    const real slope = BODY[4], tol = @TOL@;
    int n = make_room(S(x), length(x)), it;
    const real last = S(x)[n - 1];
    real lo = R(0.0), hi = R(0.0), y_lo = R(0.0), y_hi = R(0.0), u_hat = last, y_now;
    y_now = branch_output(last, x, n);
    if (FABS(target - y_now) <= R(REST_TOL) * max2(R(1.0), FABS(y_now))) target = y_now;
    if (target > y_now) {
        lo = last; y_lo = y_now; hi = R(1.0);
        y_hi = branch_output(hi, x, n);
        if (target > y_hi) u_hat = R(1.0) + (target - y_hi) / slope;
    } else if (target < y_now) {
        lo = R(-1.0); hi = last; y_hi = y_now;
        y_lo = branch_output(lo, x, n);
        if (target < y_lo) u_hat = R(-1.0) + (target - y_lo) / slope;
    }
    if (target != y_now && y_lo <= target && target <= y_hi) {
        const int rising = target > y_now;
        for (it = 0; it < 200; it++) {
            real mid, y_mid;
            if (hi - lo <= tol) break;
            mid = R(0.5) * (lo + hi);
            y_mid = branch_output(mid, x, n);
            if (rising ? y_mid < target : y_mid <= target) {
                lo = mid; y_lo = y_mid;
            } else {
                hi = mid; y_hi = y_mid;
            }
        }
        u_hat = lo + (target - y_lo) * (hi - lo) / (y_hi - y_lo);
    }
    n = update(x, n, min2(R(1.0), max2(R(-1.0), u_hat)));
    x[0] = (real)n;
    return u_hat;
}
"""
