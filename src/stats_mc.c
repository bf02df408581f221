/* The completeness magnitude by b-value stability (Cao & Gao 2002; Woessner & Wiemer, BSSA
 * 95, 684, 2005): the lowest candidate Mc whose b-value differs from the mean of the
 * b-values at Mc, Mc + dm, ... up to Mc + range by at most its own (Shi & Bolt) error.  As
 * SeismoStats computes it (4605c4e, seismostats/analysis/estimate_mc.py,
 * estimate_mc_b_stability, with its classic estimator, bk_b_tinti), numpy's floating-point
 * ranges included, so that its published values are reproduced. */
#include "bksim/stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The length of numpy's arange(start, stop, step): ceil((stop - start) / step). */
static size_t arange_length(double start, double stop, double step)
{
    double n = ceil((stop - start) / step);
    return n > 0.0 ? (size_t)n : 0;
}

static double to_bin(double x, double dx)
{
    return floor(x / dx + 0.5 + 1e-12) * dx;
}

int bk_mc_b_stability(const double *m, size_t n, double dm, double range, bk_mc_stability *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(isfinite(dm) && dm > 0.0) || !(isfinite(range) && range >= dm))
        return BK_FAIL(err, BK_ERR_INVALID, "Mc by b-stability: dm = %g, range = %g: allowed 0 < dm <= range", dm,
                       range);
    if (n < 2)
        return BK_FAIL(err, BK_ERR_INVALID, "Mc by b-stability: %zu magnitudes: needs at least 2", n);
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(m[i]))
            return BK_FAIL(err, BK_ERR_INVALID, "Mc by b-stability: magnitude %zu is %g: must be finite", i, m[i]);
        lo = fmin(lo, m[i]);
        hi = fmax(hi, m[i]);
    }
    size_t steps = arange_length(0.0, range, dm);
    size_t n_candidates = arange_length(lo, hi, dm);
    if (n_candidates <= steps)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "Mc by b-stability: magnitudes from %g to %g span %zu bins of %g: the test needs more than %zu",
                       lo, hi, n_candidates, dm, steps);
    n_candidates -= steps - 1; /* the last candidates have no range above them */
    out->range = range;
    out->steps = steps;
    for (size_t c = 0; c < n_candidates; ++c) {
        double mc = to_bin(lo + (double)c * dm, dm);
        bk_b_estimate at;
        bk_error ignored = {0};
        if (bk_b_tinti(m, n, mc, dm, &at, &ignored) != BK_OK)
            continue;
        double sum = 0.0;
        size_t plus = arange_length(mc, mc + range, dm);
        for (size_t k = 0; k < plus; ++k) {
            double mk = mc + (double)k * dm;
            if (mk > hi)
                break;
            bk_b_estimate ex;
            if (bk_b_tinti(m, n, mk, dm, &ex, &ignored) == BK_OK)
                sum += ex.b;
        }
        double diff = fabs(sum / (double)steps - at.b) / at.sigma;
        out->n_tested = c + 1;
        if (diff <= 1.0) {
            out->mc = mc;
            out->b = at.b;
            out->diff = diff;
            out->found = 1;
            return BK_OK;
        }
    }
    return BK_FAIL(err, BK_ERR_INVALID,
                   "Mc by b-stability: none of the %zu candidates from %g up has a b-value within its error of the "
                   "mean over the next %g",
                   out->n_tested, to_bin(lo, dm), range);
}
