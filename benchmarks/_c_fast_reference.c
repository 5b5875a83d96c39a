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
                           const double *knee, double cap, double dt, double *y, int guarded)
{
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
        y[i] = acc;
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
    mpl_run(u, n, x, n_cells, i_s, v_t, w, v_b, knee, cap, dt, y, 1);
}

void mpl_fast_unguarded(const double *u, int64_t n, double *x, int64_t n_cells,
                        const double *i_s, const double *v_t, const double *w, double v_b,
                        const double *knee, double cap, double dt, double *y)
{
    mpl_run(u, n, x, n_cells, i_s, v_t, w, v_b, knee, cap, dt, y, 0);
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
