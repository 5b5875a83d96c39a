/* The fastest plain C of two families' forward recursions: the yardstick of issue 29.
 *
 * benchmarks/bench_kernels.py compiles this file in the same run as it times, with
 * `cc -O3 -march=native -fno-math-errno -shared -fPIC` and states every kernel's speed as a
 * ratio to it. No -ffast-math: the results must stay those of the model (see below);
 * -fno-math-errno changes no result, it only lets the compiler treat exp and pow as pure
 * functions (keep values in registers across the calls, schedule around them).
 *
 * mpl_fast: the mPL recursion of hystkit.models.mpl.kernels.simulate (forward Euler, eq. 5.6;
 * sinh resistor continued by straight lines beyond the knee, eq. 5.29 as corrected), with
 * - one exp per cell and sample: sinh(a) = (e - 1/e) / 2, e = exp(a);
 * - below |a| = 0.5 the odd Taylor series of sinh up to a^15 instead (Estrin's scheme, in
 *   parallel with the exp, then selected): there (e - 1/e) / 2 cancels and its relative
 *   error grows as eps / |a|, which a nearly linear cell (V_T ~ 1e3, as fits produce, a ~ 1e-3)
 *   turns into ~1e-13 relative on every step of its state. mpl_fast_unguarded drops the series,
 *   to show what the guard costs and what it saves;
 * - everything that does not change per sample taken out of the loop: 1 / V_T, 2 I_S dt, the
 *   straight branch as x += s c0 + cap dt v (s the sign of v).
 * The results differ from libm's sinh in the last bits, not more (bench_kernels.py measures
 * the largest relative difference of the outputs against the numba kernel).
 *
 * pl_fast: the Power-Law recursion of hystkit.models.pl.kernels.simulate (eq. 2.16-2.18): one
 * pow per cell and sample (a real power: no cheaper correct form in general), the per-cell
 * constants out of the loop, then the output's piecewise-linear inverse (eq. 2.18).
 *
 * Cells are independent given the input, so the out-of-order core overlaps their exp/pow
 * calls; gcc does not vectorise a loop that calls libm's exp or pow without -ffast-math
 * (glibc declares its vector versions only then).
 */

#include <math.h>
#include <stdint.h>

/* Sizes as compile-time constants: bench_kernels.py also builds this file once per model with
 * -DFIX_A=.. [-DFIX_B=.. -DFIX_C=..] (its "C fixed" column), each function's size arguments in
 * order replaced by them, as a C programmer writing for one model (or hystkit export) would
 * have them: loops fully unrolled, no trip-count tests. The ratios stay to the runtime-sized
 * build, which takes its sizes as the numba kernels do. */
#ifdef FIX_A
#define FIXED_A(v) ((int64_t)(FIX_A))
#else
#define FIXED_A(v) (v)
#endif
#ifdef FIX_B
#define FIXED_B(v) ((int64_t)(FIX_B))
#else
#define FIXED_B(v) (v)
#endif
#ifdef FIX_C
#define FIXED_C(v) ((int64_t)(FIX_C))
#else
#define FIXED_C(v) (v)
#endif

/* sinh(a) for |a| < 0.5: a (1 + a^2/3! + ... + a^14/15!); the next term is < 5e-20 relative */
static inline double sinh_series(double a)
{
    const double a2 = a * a, a4 = a2 * a2, a8 = a4 * a4;
    const double p01 = 1.0 + a2 * (1.0 / 6.0);
    const double p23 = 1.0 / 120.0 + a2 * (1.0 / 5040.0);
    const double p45 = 1.0 / 362880.0 + a2 * (1.0 / 39916800.0);
    const double p67 = 1.0 / 6227020800.0 + a2 * (1.0 / 1307674368000.0);
    return a * ((p01 + a4 * p23) + a8 * (p45 + a4 * p67));
}

/* u[n]: input; x[n_cells]: state, updated in place (the caller passes a copy of x0);
 * i_s, v_t, knee[n_cells]; w[n_cells + 1]; y[n]: output. Same signature as _c_reference.c. */
static inline void mpl_run(const double *u, int64_t n, double *x, int64_t n_cells,
                           const double *i_s, const double *v_t, const double *w, double v_b,
                           const double *knee, double cap, double dt, double *y, int guarded,
                           const double *gc)
{
    n_cells = FIXED_A(n_cells);
    double inv_vt[n_cells], c2[n_cells], c0[n_cells];
    const double cap_dt = cap * dt;
    for (int64_t k = 0; k < n_cells; ++k) {
        inv_vt[k] = 1.0 / v_t[k];
        c2[k] = 2.0 * i_s[k] * dt;
        /* f = s f(knee) + cap (v - s knee) = s (f(knee) - cap knee) + cap v beyond the knee */
        c0[k] = isinf(knee[k]) ? 0.0 : (2.0 * i_s[k] * sinh(knee[k] / v_t[k]) - cap * knee[k]) * dt;
    }
    for (int64_t i = 0; i < n; ++i) {
        const double ui = u[i];
        double acc = w[0] * ui - v_b;
        for (int64_t k = 0; k < n_cells; ++k)
            acc += w[k + 1] * x[k];
        /* mpl-g: the output resistor g(z), a cubic (eq. 5.16-5.17), Horner */
        y[i] = gc ? gc[0] + acc * (gc[1] + acc * (gc[2] + acc * gc[3])) : acc;
        for (int64_t k = 0; k < n_cells; ++k) {
            const double v = ui - x[k];
            if (fabs(v) <= knee[k]) {
                const double a = v * inv_vt[k];
                const double e = exp(a);
                const double sh = 0.5 * (e - 1.0 / e);
                x[k] += c2[k] * (guarded && fabs(a) < 0.5 ? sinh_series(a) : sh);
            } else {
                x[k] += (v > 0.0 ? c0[k] : -c0[k]) + cap_dt * v;
            }
        }
    }
}

void mpl_fast(const double *u, int64_t n, double *x, int64_t n_cells, const double *i_s,
              const double *v_t, const double *w, double v_b, const double *knee, double cap,
              double dt, double *y)
{
    mpl_run(u, n, x, n_cells, i_s, v_t, w, v_b, knee, cap, dt, y, 1, 0);
}

void mpl_fast_unguarded(const double *u, int64_t n, double *x, int64_t n_cells,
                        const double *i_s, const double *v_t, const double *w, double v_b,
                        const double *knee, double cap, double dt, double *y)
{
    mpl_run(u, n, x, n_cells, i_s, v_t, w, v_b, knee, cap, dt, y, 0, 0);
}

/* mpl_g_fast: the ch. 7 compensator of hystkit.models.mpl_g.kernels.simulate: the mPL's cells
 * (mpl_fast's loop) read out through the cubic output resistor g (gc[4]); arguments as
 * mpl_fast, then gc. */
void mpl_g_fast(const double *u, int64_t n, double *x, int64_t n_cells, const double *i_s,
                const double *v_t, const double *w, double v_b, const double *knee, double cap,
                double dt, double *y, const double *gc)
{
    mpl_run(u, n, x, n_cells, i_s, v_t, w, v_b, knee, cap, dt, y, 1, gc);
}

/* mpl_poly_fast: the polynomial mPL of hystkit.models.mpl_poly.kernels.simulate: cells
 * x_k += f_k(u - x_k) dt with the cubic cell resistors f_k (fc[n_cells * 4]), continued beyond
 * the knees (knees[n_cells * 2]: x-, x+) by straight lines of slope s when limit; output the
 * cubic g (gc[4]) of w_0 u + sum w_k x_k - V_b. No libm call; f_k at the knees computed once
 * per run, not per sample. (The kernel's divergence check, a compare per cell, is left out:
 * with the limit the cells are bounded.) */
void mpl_poly_fast(const double *u, int64_t n, double *x, int64_t n_cells, const double *fc,
                   const double *knees, double s, int64_t limit, const double *gc,
                   const double *w, double v_b, double dt, double *y)
{
    n_cells = FIXED_A(n_cells);
    double fb_m[n_cells], fb_p[n_cells];
    for (int64_t k = 0; k < n_cells; ++k) {
        const double *c = fc + 4 * k, xm = knees[2 * k], xp = knees[2 * k + 1];
        fb_m[k] = c[0] + xm * (c[1] + xm * (c[2] + xm * c[3]));
        fb_p[k] = c[0] + xp * (c[1] + xp * (c[2] + xp * c[3]));
    }
    for (int64_t i = 0; i < n; ++i) {
        const double ui = u[i];
        double acc = w[0] * ui - v_b;
        for (int64_t k = 0; k < n_cells; ++k)
            acc += w[k + 1] * x[k];
        y[i] = gc[0] + acc * (gc[1] + acc * (gc[2] + acc * gc[3]));
        for (int64_t k = 0; k < n_cells; ++k) {
            const double *c = fc + 4 * k, xm = knees[2 * k], xp = knees[2 * k + 1];
            const double v = ui - x[k];
            double f;
            if (limit && v >= xp)
                f = fb_p[k] + s * (v - xp);
            else if (limit && v <= xm)
                f = fb_m[k] + s * (v - xm);
            else
                f = c[0] + v * (c[1] + v * (c[2] + v * c[3]));
            x[k] += f * dt;
        }
    }
}

/* i = f^-1(acc) for the increasing PWL output f = sum a_j phi_j, f(0) = 0 (eq. 2.18); the
 * walk of hystkit.models.pl.kernels._f_inverse */
static inline double pl_f_inverse(double u, const double *brk, int64_t m, const double *a)
{
    int64_t j0 = 0;
    while (j0 < m - 1 && brk[j0 + 1] <= 0.0)
        ++j0;
    int64_t j = j0;
    double f_left = 0.0, i_left = 0.0;
    if (u >= 0.0) {
        while (j < m - 1 && f_left + a[j] * (brk[j + 1] - i_left) < u) {
            f_left += a[j] * (brk[j + 1] - i_left);
            i_left = brk[j + 1];
            ++j;
        }
        return i_left + (u - f_left) / a[j];
    }
    while (j > 0 && f_left - a[j] * (i_left - brk[j]) > u) {
        f_left -= a[j] * (i_left - brk[j]);
        i_left = brk[j];
        --j;
    }
    return i_left + (u - f_left) / a[j];
}

/* Arguments as hystkit.models.pl.kernels.simulate: i_t, thr[n_cells], knee[n_cells], power,
 * g_lin, dt, w[n_cells + 1], v_b, brk[m + 1], a[m]; y[n]: output current. */
void pl_fast(const double *u, int64_t n, double *x, int64_t n_cells, double i_t,
             const double *thr, const double *knee, double power, double g_lin, double dt,
             const double *w, double v_b, const double *brk, int64_t m, const double *a,
             double *y)
{
    n_cells = FIXED_A(n_cells);
    m = FIXED_B(m);
    double inv_thr[n_cells], c0[n_cells];
    const double scale_dt = i_t / (power - 1.0) * dt, g_dt = g_lin * dt;
    for (int64_t k = 0; k < n_cells; ++k) {
        inv_thr[k] = 1.0 / thr[k];
        /* beyond the knee: s (scale (knee / thr)^p + G (|v| - knee)) = s c0 + G v */
        c0[k] = isinf(knee[k]) ? 0.0
                : scale_dt * pow(knee[k] / thr[k], power) - g_dt * knee[k];
    }
    for (int64_t i = 0; i < n; ++i) {
        const double ui = u[i];
        double acc = w[0] * ui - v_b;
        for (int64_t k = 0; k < n_cells; ++k)
            acc += w[k + 1] * x[k];
        y[i] = pl_f_inverse(acc, brk, m, a);
        for (int64_t k = 0; k < n_cells; ++k) {
            const double v = ui - x[k];
            const double mag = fabs(v);
            if (mag <= knee[k])
                x[k] += copysign(scale_dt * pow(mag * inv_thr[k], power), v);
            else
                x[k] += (v >= 0.0 ? c0[k] : -c0[k]) + g_dt * v;
        }
    }
}

/* pi_fast: the Prandtl-Ishlinskii model with creep of hystkit.models.pi.kernels.simulate
 * (eq. 2.11-2.15): plays p_i = max(x - r_i, min(x + r_i, p_i)), creep z_j += c_j (x - z_j),
 * v = b + w_H . p + w_K . z, y = sum_k w_Sk S_dk(v). No libm call; measured choices (10
 * plays, 4 creep operators, 5 dead zones; ns/sample): max and min as compare and select, not
 * fmax / fmin, whose IEEE NaN rules cost a blend sequence each (38 -> 14); the states moved in
 * loops of their own before the sums, so the moves vectorise and the sums do not wait on each
 * store (14 -> 7); the dead zones' sign test done once, out of the loop (three sums).
 * p[n_play], z[n_creep] updated in place; d_s, w_s[n_dz]. */
void pi_fast(const double *u, int64_t n, double *restrict p, int64_t n_play, double *restrict z,
             int64_t n_creep, const double *restrict r, const double *restrict w_h,
             const double *d_s, const double *w_s, int64_t n_dz, const double *restrict c,
             const double *restrict w_k, double b, double *y)
{
    n_play = FIXED_A(n_play);
    n_creep = FIXED_B(n_creep);
    n_dz = FIXED_C(n_dz);
    double d_pos[n_dz], w_pos[n_dz], d_neg[n_dz], w_neg[n_dz], w_zero = 0.0;
    int64_t n_pos = 0, n_neg = 0;
    for (int64_t k = 0; k < n_dz; ++k) {
        if (d_s[k] > 0.0) {
            d_pos[n_pos] = d_s[k];
            w_pos[n_pos++] = w_s[k];
        } else if (d_s[k] < 0.0) {
            d_neg[n_neg] = d_s[k];
            w_neg[n_neg++] = w_s[k];
        } else {
            w_zero += w_s[k];
        }
    }
    for (int64_t t = 0; t < n; ++t) {
        const double x = u[t];
        for (int64_t i = 0; i < n_play; ++i) {
            const double lo = x - r[i], hi = x + r[i];
            const double q = p[i] < hi ? p[i] : hi;
            p[i] = q > lo ? q : lo;
        }
        for (int64_t j = 0; j < n_creep; ++j)
            z[j] += c[j] * (x - z[j]);
        double v = b;
        for (int64_t i = 0; i < n_play; ++i)
            v += w_h[i] * p[i];
        for (int64_t j = 0; j < n_creep; ++j)
            v += w_k[j] * z[j];
        double acc = w_zero * v;
        for (int64_t k = 0; k < n_pos; ++k) {
            const double e = v - d_pos[k];
            acc += w_pos[k] * (e > 0.0 ? e : 0.0);  /* maxsd, no branch */
        }
        for (int64_t k = 0; k < n_neg; ++k) {
            const double e = v - d_neg[k];
            acc += w_neg[k] * (e < 0.0 ? e : 0.0);
        }
        y[t] = acc;
    }
}

/* preisach_fast: the Preisach models of hystkit.models.preisach and .gpreisach
 * (kernels.forward: kernels.run_tables, then the output equation and the straight-line
 * extension beyond [-1, 1]). The staircase of dominant extrema s[0 .. ns-1] with the running
 * sums c[i][k] of the closed segments' terms (eq. 9.13) per Everett table k, so a sample costs
 * one bilinear interpolation per table (two at a reversal) and the wiping-out is a pop; no
 * libm call. Output: the tables' relay parts (weighted: mixed by w = (1 + u) / 2, the
 * generalised model's eq. 2.2), plus the polynomial poly[n_poly] (Horner; the classical
 * model's is its offset), plus slope (u - clip(u)).
 * A[K * L * L]: the antisymmetric Everett tables (row-major); s[capacity] holds the start
 * staircase of length *ns on entry and the final one on return. */
static inline double preisach_everett(const double *A, int64_t L, double scale, double a,
                                      double b)
{
    const double xa = (a + 1.0) * scale, xb = (b + 1.0) * scale;
    int64_t ia = (int64_t)xa, ib = (int64_t)xb;
    ia = ia < L - 2 ? ia : L - 2;
    ib = ib < L - 2 ? ib : L - 2;
    const double sa = xa - ia, sb = xb - ib;
    const double *r0 = A + ia * L + ib, *r1 = r0 + L;
    return (1.0 - sa) * ((1.0 - sb) * r0[0] + sb * r0[1])
           + sa * ((1.0 - sb) * r1[0] + sb * r1[1]);
}

static inline double preisach_term(const double *A, int64_t L, double scale, double p, double q)
{
    return q >= p ? preisach_everett(A, L, scale, q, p) : -preisach_everett(A, L, scale, p, q);
}

static inline void preisach_run(const double *u, int64_t n, double *s, int64_t *ns,
                                int64_t capacity, const double *A, int64_t L, int64_t K,
                                int64_t weighted, const double *poly, int64_t n_poly,
                                double slope, double *y)
{
    const double scale = 0.5 * (L - 1);
    double c[capacity * K], f0[K], relay[K];
    for (int64_t k = 0; k < K; ++k)
        f0[k] = -A[k * L * L + (L - 1) * L];
    int64_t m = *ns;
    for (int64_t k = 0; k < K; ++k)
        c[k] = 0.0;
    for (int64_t i = 1; i < m - 1; ++i)
        for (int64_t k = 0; k < K; ++k)
            c[i * K + k] = c[(i - 1) * K + k]
                           + preisach_term(A + k * L * L, L, scale, s[i - 1], s[i]);
    for (int64_t t = 0; t < n; ++t) {
        if (m >= capacity - 1) {  /* forget the innermost closed loop before a push */
            s[m - 3] = s[m - 1];
            m -= 2;
        }
        const double ut = u[t], uc = fmin(1.0, fmax(-1.0, ut));
        const double last = s[m - 1];
        if (uc != last) {
            if (m == 1) {
                s[1] = uc;
                m = 2;
            } else if ((uc > last) == (last > s[m - 2])) {
                s[m - 1] = uc;
            } else {  /* a reversal closes the last segment */
                for (int64_t k = 0; k < K; ++k)
                    c[(m - 1) * K + k] = c[(m - 2) * K + k]
                                         + preisach_term(A + k * L * L, L, scale, s[m - 2], last);
                s[m++] = uc;
            }
            while (m >= 3) {
                const int rising = s[m - 1] > s[m - 2];
                if (rising ? s[m - 1] >= s[m - 3] : s[m - 1] <= s[m - 3]) {
                    s[m - 3] = s[m - 1];
                    m -= 2;
                } else {
                    break;
                }
            }
        }
        for (int64_t k = 0; k < K; ++k)
            relay[k] = m == 1 ? f0[k]
                : f0[k] + 2.0 * (c[(m - 2) * K + k]
                                 + preisach_term(A + k * L * L, L, scale, s[m - 2], s[m - 1]));
        double out = relay[0];
        if (weighted) {
            const double w = 0.5 * (1.0 + uc);
            out = (1.0 - w) * relay[0] + w * relay[1];
        }
        double r = 0.0;
        for (int64_t j = n_poly - 1; j >= 0; --j)
            r = r * uc + poly[j];
        y[t] = out + r + slope * (ut - uc);
    }
    *ns = m;
}

void preisach_fast(const double *u, int64_t n, double *s, int64_t *ns, int64_t capacity,
                   const double *A, int64_t L, int64_t K, int64_t weighted, const double *poly,
                   int64_t n_poly, double slope, double *y)
{
    L = FIXED_A(L);
    capacity = FIXED_B(capacity);
    K = FIXED_C(K);
    /* the classical model (one table, no weight, the offset) as a copy of its own: the
     * constants fold (measured 9.8 -> 7.6 ns/sample, 20 levels) */
    if (K == 1 && !weighted && n_poly == 1)
        preisach_run(u, n, s, ns, capacity, A, L, 1, 0, poly, 1, slope, y);
    else
        preisach_run(u, n, s, ns, capacity, A, L, K, weighted, poly, n_poly, slope, y);
}

/* boucwen_fast: the Bouc-Wen oscillator of hystkit.models.boucwen.kernels.simulate: per
 * sample n_sub classical RK4 substeps of m y'' + c y' + k y + z = u, z' = alpha v - beta |v|
 * |z|^(nu-1) z - gamma v |z|^nu, the force linear over the sample (linear) or held. |z|^nu is
 * |z| for nu = 1 (what fits give) and pow otherwise, chosen once out of the loop; the rest is
 * the kernel's arithmetic. A serial dependency chain: nothing to vectorise.
 * x[4] = (y, v, z, u_prev) one sample before u[0] (fresh: at u[0] itself, y[0] = x[0]). */
static inline void boucwen_rhs(double y, double v, double z, double u, const double *th,
                               double inv_m, int nu_one, double *dy, double *dv, double *dz)
{
    const double p = nu_one ? fabs(z) : pow(fabs(z), th[6]);
    const double q = z >= 0.0 ? p : -p;
    *dy = v;
    *dv = (u - th[1] * v - th[2] * y - z) * inv_m;
    *dz = th[3] * v - th[4] * fabs(v) * q - th[5] * v * p;
}

void boucwen_fast(const double *u, int64_t n, double *x, int64_t fresh, const double *th,
                  double dt, int64_t n_sub, int64_t linear, double *out)
{
    n_sub = FIXED_A(n_sub);
    const int nu_one = th[6] == 1.0;
    const double inv_m = 1.0 / th[0];  /* one division per run, not eight per sample */
    const double h = dt / n_sub;
    double y = x[0], v = x[1], z = x[2], u_prev = x[3];
    for (int64_t i = 0; i < n; ++i) {
        if (i > 0 || !fresh) {
            const double du = linear ? (u[i] - u_prev) / n_sub : 0.0;
            for (int64_t j = 0; j < n_sub; ++j) {
                const double u0 = u_prev + j * du, u1 = u0 + 0.5 * du, u2 = u0 + du;
                double k1y, k1v, k1z, k2y, k2v, k2z, k3y, k3v, k3z, k4y, k4v, k4z;
                boucwen_rhs(y, v, z, u0, th, inv_m, nu_one, &k1y, &k1v, &k1z);
                boucwen_rhs(y + 0.5 * h * k1y, v + 0.5 * h * k1v, z + 0.5 * h * k1z, u1, th,
                            inv_m, nu_one, &k2y, &k2v, &k2z);
                boucwen_rhs(y + 0.5 * h * k2y, v + 0.5 * h * k2v, z + 0.5 * h * k2z, u1, th,
                            inv_m, nu_one, &k3y, &k3v, &k3z);
                boucwen_rhs(y + h * k3y, v + h * k3v, z + h * k3z, u2, th, inv_m, nu_one, &k4y, &k4v,
                            &k4z);
                y += h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
                v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
                z += h / 6.0 * (k1z + 2.0 * k2z + 2.0 * k3z + k4z);
            }
        }
        out[i] = y;
        u_prev = u[i];
    }
    x[0] = y, x[1] = v, x[2] = z, x[3] = u_prev;
}

/* chua_fast: the Chua-Stromsmoe elements of hystkit.models.chua.kernels.simulate (eq. 2.3,
 * forward Euler): per element y_k += dt g_k(u - f_k(y_k)), output y = sum_k y_k, with the
 * restoring function f(y) = k_inf y + (k0 - k_inf) y_s tanh(y / y_s) and the dissipation g: 0
 * in the dead band |v| <= band, s G V_g sinh((|v| - band) / V_g) up to the knee, then the
 * straight line of slope cap. Two libm calls per element and sample: tanh, and expm1 for the
 * sinh, sinh(a) = (t + t / (t + 1)) / 2 with t = expm1(a), a >= 0 (no cancellation near 0, so
 * no series guard); per-element constants (1 / y_s, 1 / V_g, the knee's line) out of the loop.
 * x[n_el] updated in place; k0, k_inf, y_s, g, v_g, band, knee, cap [n_el]. */
void chua_fast(const double *u, int64_t n, double *x, int64_t n_el, const double *k0,
               const double *k_inf, const double *y_s, const double *g, const double *v_g,
               const double *band, const double *knee, const double *cap, double dt, double *y)
{
    n_el = FIXED_A(n_el);
    double inv_ys[n_el], dk_ys[n_el], inv_vg[n_el], gvg_dt[n_el], c0[n_el], cap_dt[n_el];
    for (int64_t k = 0; k < n_el; ++k) {
        inv_ys[k] = 1.0 / y_s[k];
        dk_ys[k] = (k0[k] - k_inf[k]) * y_s[k];
        inv_vg[k] = 1.0 / v_g[k];
        gvg_dt[k] = g[k] * v_g[k] * dt;
        cap_dt[k] = cap[k] * dt;
        /* beyond the knee: s (G V_g sinh((knee - band) / V_g) + cap (|v| - knee)) dt
         * = s c0 + cap dt v */
        c0[k] = isinf(knee[k]) ? 0.0
                : (g[k] * v_g[k] * sinh((knee[k] - band[k]) / v_g[k]) - cap[k] * knee[k]) * dt;
    }
    for (int64_t i = 0; i < n; ++i) {
        const double ui = u[i];
        double acc = 0.0;
        for (int64_t k = 0; k < n_el; ++k) {
            const double v = ui - (k_inf[k] * x[k] + dk_ys[k] * tanh(x[k] * inv_ys[k]));
            const double a = fabs(v);
            double step = 0.0;
            if (a > knee[k]) {
                step = (v > 0.0 ? c0[k] : -c0[k]) + cap_dt[k] * v;
            } else if (a > band[k]) {
                const double t = expm1((a - band[k]) * inv_vg[k]);
                const double sh = 0.5 * (t + t / (t + 1.0));
                step = v > 0.0 ? gvg_dt[k] * sh : -gvg_dt[k] * sh;
            }
            x[k] += step;
            acc += x[k];
        }
        y[i] = acc;
    }
}

/* bobbio_fast: the Bobbio-Marrucci chain of hystkit.models.bobbio (kernels.forces, then the
 * output the wrapper forms): the spring forces F_2..F_N clipped from the loaded end inwards,
 * F_k+1 = min(max(F_k+1, F_k - a_k), F_k + a_k) (eq. 2.5), y = c_1 u + sum_k c_k+1 F_k+1 + b,
 * in one pass. x[n_f] (n_f = N - 1) updated in place; a[n_f], c[n_f + 1]. */
void bobbio_fast(const double *u, int64_t n, double *x, int64_t n_f, const double *a,
                 const double *c, double b, double *y)
{
    n_f = FIXED_A(n_f);
    for (int64_t i = 0; i < n; ++i) {
        double prev = u[i], acc = c[0] * u[i];
        for (int64_t k = 0; k < n_f; ++k) {
            const double lo = prev - a[k], hi = prev + a[k];
            double f = x[k] > lo ? x[k] : lo;
            f = f < hi ? f : hi;
            x[k] = f;
            prev = f;
            acc += c[k + 1] * f;
        }
        y[i] = acc + b;
    }
}

/* ladder_fast: the PWL ladder of hystkit.models.ladder (kernels.states, then the output the
 * wrapper forms): y = w_0 e + sum_k w_k U_k - V_b from the present capacitor voltages, then
 * one forward-Euler step, U_k += dt (i_k - i_k+1), i_k the dead-zone current g_k dz(U_k-1 -
 * U_k, band_k) (U_0 = e), all currents from the old voltages. No libm call.
 * x[n_cells] updated in place; band, g [n_cells]; w[n_cells + 1]. */
void ladder_fast(const double *u, int64_t n, double *x, int64_t n_cells, const double *band,
                 const double *g, const double *w, double v_b, double dt, double *y)
{
    n_cells = FIXED_A(n_cells);
    for (int64_t i = 0; i < n; ++i) {
        const double e = u[i];
        double acc = w[0] * e - v_b;
        for (int64_t k = 0; k < n_cells; ++k)
            acc += w[k + 1] * x[k];
        y[i] = acc;
        const double v = e - x[0];
        double i_in = v > band[0] ? g[0] * (v - band[0]) : v < -band[0] ? g[0] * (v + band[0])
                      : 0.0;
        for (int64_t k = 0; k < n_cells; ++k) {
            double i_out = 0.0;  /* from the old voltages: x[k + 1] is not yet updated */
            if (k + 1 < n_cells) {
                const double vo = x[k] - x[k + 1];
                i_out = vo > band[k + 1] ? g[k + 1] * (vo - band[k + 1])
                        : vo < -band[k + 1] ? g[k + 1] * (vo + band[k + 1]) : 0.0;
            }
            x[k] += dt * (i_in - i_out);
            i_in = i_out;
        }
    }
}
