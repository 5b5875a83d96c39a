"""Preisach staircase models (``models/preisach/kernels.py``, shared by the classical and the
generalised family): ``block_forward`` / ``block_inverse`` and the rest state.

Body: ``[capacity, L, K, weighted, slope, tol, n_poly, poly (n_poly), A (K L L)]``. The state
is the block's (``[n, s_0 .. s_{capacity-1}]``) followed by the running sums ``c`` (capacity x
K) that the run kernels keep and the block rebuilds every sample: kept here, the cost per
sample is amortised O(1) instead of O(n), and the sums are the same additions in the same
order, so the numbers are too. The rest state is the demagnetised staircase moved by one
sample of the value, as ``FAMILY.rest_state`` does.
"""

from __future__ import annotations

from collections.abc import Callable

from .._protocol import Translation

REST_TOL = 1e-12  # kernels.REST_TOL
# In float the inverse's tolerances (the rest test and the bisection's bracket, 1e-12 for
# double) are ~16 float epsilons: below that the bisection only collects rounding noise.
FLOAT_TOL = 2e-6
C_AFTER_LOAD = "load_sums(st->x);\n    "
M_LOAD = """function x = model_load(B, x_block)
x = zeros(round(B(1)) + 1 + round(B(1)) * round(B(3)), 1);
x(1:numel(x_block)) = x_block;
x = load_sums(B, x);
end
"""


def extra(comp) -> dict:
    """The demagnetised staircase every run starts from (``model.demagnetised_state``)."""
    from ...models.preisach.model import demagnetised_state

    return {"DEMAG": demagnetised_state(comp.structure.levels - 1)}


def _sizes(plan) -> tuple[int, int, int, int]:
    cap, levels, n_tab, n_poly = (int(plan.body[i]) for i in (0, 1, 2, 6))
    return cap, levels, n_tab, n_poly


def state_size(plan) -> int:
    cap, _, n_tab, _ = _sizes(plan)
    return cap + 1 + cap * n_tab


def c_model(plan, lit: Callable[[float], str]) -> str:
    cap, levels, n_tab, n_poly = _sizes(plan)
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


def m_model(plan, lit: Callable[[float], str]) -> str:
    """MATLAB: the staircase is ``x(2:CAP+1)`` (``s_i`` at ``x(2 + i)``), the running sums
    ``c_(i,k)`` at ``x(2 + CAP + i K + k)``, indices ``i, k`` counted from 0 as in C."""
    cap, levels, n_tab, n_poly = _sizes(plan)
    demag = "[" + ", ".join(lit(v) for v in plan.extra["DEMAG"]) + "]"
    consts = {"@CAP@": str(cap), "@LEV@": str(levels), "@K@": str(n_tab),
              "@NP@": str(n_poly), "@IA@": str(8 + n_poly), "@RT@": lit(REST_TOL)}
    code = _M_COMMON + (_M_INVERSE if plan.inverse else _M_FORWARD)
    for key, value in consts.items():
        code = code.replace(key, value)
    return f"""function x = model_rest(B, value)
d = {demag};
x = zeros(@CAP@ + 1 + @CAP@ * @K@, 1);
x(2:numel(d) + 1) = d;
x(1) = numel(d);
x = load_sums(B, x);
[out, x] = model_step(B, x, value);
end
""".replace("@CAP@", str(cap)).replace("@K@", str(n_tab)) + code


_M_COMMON = """
function v = A(B, k, i, j)
v = B(@IA@ + (k * @LEV@ + i) * @LEV@ + j);
end

function v = everett(B, k, a, b)
scale = 0.5 * (@LEV@ - 1);
xa = (a + 1.0) * scale; xb = (b + 1.0) * scale;
ia = min(fix(xa), @LEV@ - 2); ib = min(fix(xb), @LEV@ - 2);
sa = xa - ia; sb = xb - ib;
i0 = @IA@ + (k * @LEV@ + ia) * @LEV@ + ib;  % A(k, ia, ib), inlined: calls are slow in Octave
v = ((1.0 - sa) * ((1.0 - sb) * B(i0) + sb * B(i0 + 1)) ...
     + sa * ((1.0 - sb) * B(i0 + @LEV@) + sb * B(i0 + @LEV@ + 1)));
end

function v = term(B, k, p, q)
if q >= p
    v = everett(B, k, q, p);
else
    v = -everett(B, k, p, q);
end
end

function x = load_sums(B, x)
n = round(x(1));
for k = 0:@K@ - 1
    x(2 + @CAP@ + k) = 0.0;
end
for i = 1:n - 2
    for k = 0:@K@ - 1
        x(2 + @CAP@ + i * @K@ + k) = x(2 + @CAP@ + (i - 1) * @K@ + k) ...
            + term(B, k, x(2 + i - 1), x(2 + i));
    end
end
end

function [x, n] = make_room(x, n)
if n >= @CAP@ - 1
    x(2 + n - 3) = x(2 + n - 1);
    n = n - 2;
end
end

function [x, n] = update(B, x, n, u)
last = x(2 + n - 1);
if n > 1 && u ~= last && (u > last) ~= (last > x(2 + n - 2))
    for k = 0:@K@ - 1
        x(2 + @CAP@ + (n - 1) * @K@ + k) = x(2 + @CAP@ + (n - 2) * @K@ + k) ...
            + term(B, k, x(2 + n - 2), last);
    end
end
if u == last
    return;
end
if n == 1
    x(3) = u;
    n = 2;
elseif (u > last) == (last > x(2 + n - 2))
    x(2 + n - 1) = u;
else
    x(2 + n) = u;
    n = n + 1;
end
while n >= 3
    rising = x(2 + n - 1) > x(2 + n - 2);
    if (rising && x(2 + n - 1) >= x(2 + n - 3)) || (~rising && x(2 + n - 1) <= x(2 + n - 3))
        x(2 + n - 3) = x(2 + n - 1);
        n = n - 2;
    else
        break;
    end
end
end

function y = combine(B, p, u)
if B(4) ~= 0
    w = 0.5 * (1.0 + u);
    y = (1.0 - w) * p(1) + w * p(min(2, numel(p)));
else
    y = p(1);
end
r = 0.0;
for i = @NP@ - 1:-1:0
    r = r * u + B(8 + i);
end
y = y + r;
end
"""

_M_FORWARD = """
function [y, x] = model_step(B, x, u)
u_clip = min(1.0, max(-1.0, u));
n = round(x(1));
[x, n] = make_room(x, n);
[x, n] = update(B, x, n, u_clip);
acc = zeros(@K@, 1);
for k = 0:@K@ - 1
    acc(k + 1) = -A(B, k, @LEV@ - 1, 0);
    if n > 1
        acc(k + 1) = -A(B, k, @LEV@ - 1, 0) + 2.0 * (x(2 + @CAP@ + (n - 2) * @K@ + k) ...
                     + term(B, k, x(2 + n - 2), x(2 + n - 1)));
    end
end
x(1) = n;
y = combine(B, acc, u_clip) + B(5) * (u - u_clip);
end
"""

_M_INVERSE = """
function found = last_index(x, start, stop, u, above)
found = -1;
if stop < start
    return;
end
lo = 0; hi = fix((stop - start) / 2);
while lo <= hi
    mid = fix((lo + hi) / 2);
    j = start + 2 * mid;
    if above
        hit = x(2 + j) > u;
    else
        hit = x(2 + j) < u;
    end
    if hit
        found = j;
        lo = mid + 1;
    else
        hi = mid - 1;
    end
end
end

function v = running_sum(B, x, n, i, k)
if i <= n - 2
    v = x(2 + @CAP@ + i * @K@ + k);
else
    v = x(2 + @CAP@ + (n - 2) * @K@ + k) + term(B, k, x(2 + n - 2), x(2 + n - 1));
end
end

function y = branch_output(B, u, x, n)
acc = zeros(@K@, 1);
if u >= x(2 + n - 1)
    i = last_index(x, 1, n - 2, u, true) + 1;
    for k = 0:@K@ - 1
        if i > 0
            base = running_sum(B, x, n, i, k);
        else
            base = 0.0;
        end
        acc(k + 1) = -A(B, k, @LEV@ - 1, 0) + 2.0 * (base + everett(B, k, u, x(2 + i)));
    end
else
    i = last_index(x, 0, n - 2, u, false);
    for k = 0:@K@ - 1
        if i < 0
            acc(k + 1) = -A(B, k, @LEV@ - 1, 0);
        else
            acc(k + 1) = -A(B, k, @LEV@ - 1, 0) + 2.0 * (running_sum(B, x, n, i + 1, k) ...
                         - everett(B, k, x(2 + i + 1), u));
        end
    end
end
y = combine(B, acc, u);
end

function [u_hat, x] = model_step(B, x, target)
slope = B(5); tol = B(6);
[x, n] = make_room(x, round(x(1)));
last = x(2 + n - 1);
lo = 0.0; hi = 0.0; y_lo = 0.0; y_hi = 0.0; u_hat = last;
y_now = branch_output(B, last, x, n);
if abs(target - y_now) <= @RT@ * max(1.0, abs(y_now))
    target = y_now;
end
if target > y_now
    lo = last; y_lo = y_now; hi = 1.0;
    y_hi = branch_output(B, hi, x, n);
    if target > y_hi
        u_hat = 1.0 + (target - y_hi) / slope;
    end
elseif target < y_now
    lo = -1.0; hi = last; y_hi = y_now;
    y_lo = branch_output(B, lo, x, n);
    if target < y_lo
        u_hat = -1.0 + (target - y_lo) / slope;
    end
end
if target ~= y_now && y_lo <= target && target <= y_hi
    rising = target > y_now;
    for it = 1:200
        if hi - lo <= tol
            break;
        end
        mid = 0.5 * (lo + hi);
        y_mid = branch_output(B, mid, x, n);
        if (rising && y_mid < target) || (~rising && y_mid <= target)
            lo = mid; y_lo = y_mid;
        else
            hi = mid; y_hi = y_mid;
        end
    end
    u_hat = lo + (target - y_lo) * (hi - lo) / (y_hi - y_lo);
end
[x, n] = update(B, x, n, min(1.0, max(-1.0, u_hat)));
x(1) = n;
end
"""


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("A", "branch_output", "combine", "everett", "last_index", "load_sums",
                 "make_room", "running_sum", "term", "update"),
    extra=extra,
    state_size=state_size,
    m_load=M_LOAD)
