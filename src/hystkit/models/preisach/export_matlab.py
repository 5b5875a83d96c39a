"""The staircase block in MATLAB (:func:`m_model`), for :mod:`.export`: the same steps as the C
translation, as subfunctions.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from textwrap import indent

from .export_layout import REST_TOL, body_sizes

__all__ = ["m_model"]


def m_model(plan, lit: Callable[[float], str]) -> str:
    """MATLAB: the staircase is ``x(2:CAP+1)`` (``s_i`` at ``x(2 + i)``), the running sums
    ``c_(i,k)`` at ``x(2 + CAP + i K + k)``, indices ``i, k`` counted from 0 as in C. Every
    table ``k`` at once (a column) and the inverse's branch output written out in its
    bisection: Octave interprets each statement and call (a call costs several array
    operations), each table's arithmetic stays the C's."""
    cap, levels, n_tab, n_poly = body_sizes(plan)
    demag = "[" + ", ".join(lit(v) for v in plan.extra["DEMAG"]) + "]"
    i_a = 8 + n_poly
    tables = "; ".join(str(k * levels) for k in range(n_tab))
    f0 = "; ".join(str(i_a + (k * levels + levels - 1) * levels) for k in range(n_tab))
    consts = {"@CAP@": str(cap), "@LEV@": str(levels), "@K@": str(n_tab),
              "@IA@": str(i_a), "@RT@": lit(REST_TOL), "@SCALE@": lit(0.5 * (levels - 1)),
              "@KL@": f"[{tables}]" if n_tab > 1 else tables, "@F0@": f"[{f0}]"}
    combine = _combine(plan.body[3] != 0, n_tab, [lit(v) for v in plan.body[7:7 + n_poly]])
    code = re.sub(r"^( *)@COMBINE@", lambda found: indent(combine, found.group(1)),
                  _M_COMMON + (_M_INVERSE if plan.inverse else _M_FORWARD), flags=re.MULTILINE)
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


def _combine(weighted: bool, n_tab: int, poly: list[str]) -> str:
    """``y = combine(acc, u)`` (kernels.combine): the weight interpolated between tables 0 and
    1 if weighted, plus the polynomial in u (coefficients ``poly``, literals) by Horner from
    ``r = 0`` (the body says which)."""
    parts = (f"w = 0.5 * (1.0 + u);\ny = (1.0 - w) * acc(1) + w * acc({min(2, n_tab)});\n"
             if weighted else "y = acc(1);\n")
    horner = "0.0"
    for i, coefficient in enumerate(reversed(poly)):
        horner = f"0.0 * u + {coefficient}" if i == 0 else f"({horner}) * u + {coefficient}"
    return parts + f"y = y + ({horner});\n"


def _everett(a: str, b: str, a_at: str = "", b_at: str = "") -> str:
    """``E`` = E_k(a, b) of every table k (a column), bilinear in A_k (kernels._everett). An
    argument that is the staircase's ``s(j)`` (``a_at`` or ``b_at`` = j) takes its grid cell
    from ``is_(j)``, ``ss(j)``, computed once a step by the same operations (:data:`_GRID`)."""
    grid_a = (f"ia = is_({a_at}); sa = ss({a_at});\n" if a_at else
              f"xa = ({a} + 1.0) * @SCALE@; ia = min(fix(xa), @LEV@ - 2); sa = xa - ia;\n")
    grid_b = (f"ib = is_({b_at}); sb = ss({b_at});\n" if b_at else
              f"xb = ({b} + 1.0) * @SCALE@; ib = min(fix(xb), @LEV@ - 2); sb = xb - ib;\n")
    return grid_a + grid_b + """i0 = @IA@ + (@KL@ + ia) * @LEV@ + ib;
E = ((1.0 - sa) * ((1.0 - sb) * B(i0) + sb * B(i0 + 1)) ...
     + sa * ((1.0 - sb) * B(i0 + @LEV@) + sb * B(i0 + @LEV@ + 1)));
"""


# What the branch output reads of the staircase s, once a step: its entries above the first
# (s_1, s_3, ...) and below (s_0, s_2, ...) as candidates, each entry's grid cell and offset,
# -A_k(L - 1, 0)
_GRID = """s_up = s(2:2:n - 1); s_down = s(1:2:n - 1);
xs = (s + 1.0) * @SCALE@; is_ = min(fix(xs), @LEV@ - 2); ss = xs - is_;
f0 = -B(@F0@);
"""


# @KL@: the column k L of every table k; @F0@: the body indices of A_k(L - 1, 0)
_M_COMMON = f"""
function E = everett(B, a, b)
{_everett("a", "b")}end

function v = term(B, p, q)
if q >= p
    v = everett(B, q, p);
else
    v = -everett(B, p, q);
end
end

function x = load_sums(B, x)
n = round(x(1));
x(2 + @CAP@:1 + @CAP@ + @K@) = 0.0;
for i = 1:n - 2
    c = 2 + @CAP@ + i * @K@;
    x(c:c + @K@ - 1) = x(c - @K@:c - 1) + term(B, x(2 + i - 1), x(2 + i));
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
    c = 2 + @CAP@ + (n - 1) * @K@;
    x(c:c + @K@ - 1) = x(c - @K@:c - 1) + term(B, x(2 + n - 2), last);
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
"""

_M_FORWARD = """
function [y, x] = model_step(B, x, u_in)
u = min(1.0, max(-1.0, u_in));
n = round(x(1));
[x, n] = make_room(x, n);
[x, n] = update(B, x, n, u);
if n > 1
    c = 2 + @CAP@ + (n - 2) * @K@;
    acc = -B(@F0@) + 2.0 * (x(c:c + @K@ - 1) + term(B, x(2 + n - 2), x(2 + n - 1)));
else
    acc = -B(@F0@);
end
x(1) = n;
@COMBINE@y = y + B(5) * (u_in - u);
end
"""

# The output y if the input moved from the present state straight to u (kernels._branch_output;
# the staircase s = s_0 .. s_(n-1), the running sums c_(i,k) in R(:, i + 1), i = 1 .. n - 1).
# The maxima on the staircase fall and its minima rise (wiping-out), so the ones above (below) u
# are a prefix and their count gives the last one, as kernels._last_index's binary search does.
_BRANCH = f"""if u >= s(n)
    i = 2 * sum(s_up > u);
{indent(_everett("u", "", b_at="i + 1"), "    ")}    if i > 0
        acc = f0 + 2.0 * (R(:, i + 1) + E);
    else
        acc = f0 + 2.0 * (0.0 + E);
    end
else
    i = 2 * sum(s_down < u) - 2;
    if i < 0
        acc = f0;
    else
{indent(_everett("", "u", a_at="i + 2"), "        ")}        acc = f0 + 2.0 * (R(:, i + 2) - E);
    end
end
@COMBINE@"""

_M_INVERSE = f"""
function y = branch_output(B, u, s, n, R)
{_GRID}{_BRANCH}end

function [u_hat, x] = model_step(B, x, target)
slope = B(5); tol = B(6);
[x, n] = make_room(x, round(x(1)));
s = x(2:n + 1);
R = reshape(x(2 + @CAP@:1 + @CAP@ + (n - 1) * @K@), @K@, n - 1);
if n >= 2
    R(:, n) = R(:, n - 1) + term(B, s(n - 1), s(n));
end
{_GRID}last = s(n);
lo = 0.0; hi = 0.0; y_lo = 0.0; y_hi = 0.0; u_hat = last;
y_now = branch_output(B, last, s, n, R);
if abs(target - y_now) <= @RT@ * max(1.0, abs(y_now))
    target = y_now;
end
if target > y_now
    lo = last; y_lo = y_now; hi = 1.0;
    y_hi = branch_output(B, hi, s, n, R);
    if target > y_hi
        u_hat = 1.0 + (target - y_hi) / slope;
    end
elseif target < y_now
    lo = -1.0; hi = last; y_hi = y_now;
    y_lo = branch_output(B, lo, s, n, R);
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
        u = 0.5 * (lo + hi);
{indent(_BRANCH, "        ")}        if (rising && y < target) || (~rising && y <= target)
            lo = u; y_lo = y;
        else
            hi = u; y_hi = y;
        end
    end
    u_hat = lo + (target - y_lo) * (hi - lo) / (y_hi - y_lo);
end
[x, n] = update(B, x, n, min(1.0, max(-1.0, u_hat)));
x(1) = n;
end
"""
