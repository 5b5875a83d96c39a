/* Plain C reference of the mPL forward model, for benchmarks/bench_mpl.py.
 *
 * Same arithmetic, in the same order, as hystkit.models._mpl_kernels.simulate (forward Euler,
 * eq. 5.6, with the sinh resistor continued by straight lines beyond the knee, eq. 5.29 as
 * corrected in mpl.py): output from the present state first, then the state update. Keeping
 * the operation order identical (no algebraic shortcuts, no precomputed sinh(knee / v_t)) is
 * what lets the benchmark demand agreement to ~1e-12 and so compare equal work.
 *
 * Built at run time with `cc -O2 -shared -fPIC` and no -ffast-math, which would allow
 * reassociation and change the results.
 */

#include <math.h>
#include <stdint.h>

/* u[n]: input; x[n_cells]: state, updated in place (the caller passes a copy of x0);
 * i_s, v_t, knee[n_cells]; w[n_cells + 1]; y[n]: output. */
void mpl_simulate(const double *u, int64_t n, double *x, int64_t n_cells,
                  const double *i_s, const double *v_t, const double *w, double v_b,
                  const double *knee, double cap, double dt, double *y)
{
    for (int64_t i = 0; i < n; ++i) {
        double acc = w[0] * u[i] - v_b;
        for (int64_t k = 0; k < n_cells; ++k)
            acc += w[k + 1] * x[k];
        y[i] = acc;
        for (int64_t k = 0; k < n_cells; ++k) {
            double v = u[i] - x[k];
            double f;
            if (fabs(v) <= knee[k]) {
                f = 2.0 * i_s[k] * sinh(v / v_t[k]);
            } else {
                double s = v > 0 ? 1.0 : -1.0;
                f = s * 2.0 * i_s[k] * sinh(knee[k] / v_t[k]) + cap * (v - s * knee[k]);
            }
            x[k] += f * dt;
        }
    }
}
