"""The staircase block in MATLAB (:func:`m_model`), for :mod:`.export`: the same steps as the C
translation, as subfunctions.
"""

from __future__ import annotations

from collections.abc import Callable

from .export_layout import REST_TOL, body_sizes

__all__ = ["m_model"]


def m_model(plan, lit: Callable[[float], str]) -> str:
    """MATLAB: the staircase is ``x(2:CAP+1)`` (``s_i`` at ``x(2 + i)``), the running sums
    ``c_(i,k)`` at ``x(2 + CAP + i K + k)``, indices ``i, k`` counted from 0 as in C."""
    cap, levels, n_tab, n_poly = body_sizes(plan)
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
