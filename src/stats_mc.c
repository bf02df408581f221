/* The completeness magnitude by b-value stability (Cao & Gao 2002; Woessner & Wiemer, BSSA
 * 95, 684, 2005): the lowest candidate Mc whose b-value differs from the mean of the
 * b-values at Mc, Mc + dm, ... up to Mc + range by at most its own (Shi & Bolt) error.  As
 * SeismoStats computes it (4605c4e, seismostats/analysis/estimate_mc.py,
 * estimate_mc_b_stability, with its classic estimator, bk_b_tinti), numpy's floating-point
 * ranges included, so that its published values are reproduced.
 *
 * And by the Kolmogorov-Smirnov method (Clauset, Shalizi & Newman 2009; Mizrahi, Nandan &
 * Wiemer 2021), as SeismoStats' estimate_mc_ks: the lowest candidate whose magnitudes above
 * it are at most as far from their GR fit (bk_b_tinti's b) as synthetic GR samples of the
 * same size and b are from that law in a fraction p_pass of cases (0.1 by default); the
 * synthetic samples, unlike bk_gr_gof's, are not refitted, as in SeismoStats, and come from
 * a seeded MT19937 where SeismoStats' come from numpy's unseeded generator, drawn as counts
 * per bin (the same law, in O(bins) draws per sample). */
#include "bksim/stats.h"
#include "stats_impl.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_randist.h>


/* A sample of n offsets of the geometric law P(k) = (1 - q) q^k as counts per offset: the
 * law is memoryless, so of the m offsets >= j, Binomial(m, 1 - q) equal j.  O(bins) draws
 * where drawing each offset is O(n) logarithms: the KS method tests every candidate with
 * thousands of samples.  *count grows as needed (*cap entries); returns the largest offset
 * drawn, or -1 when out of memory. */
static long draw_counts(gsl_rng *rng, size_t n, double q, size_t **count, size_t *cap)
{
    long top = -1;
    for (size_t left = n; left > 0;) {
        if ((size_t)(top + 1) == *cap) {
            size_t *grown = realloc(*count, 2 * *cap * sizeof *grown);
            if (!grown)
                return -1;
            *count = grown;
            *cap *= 2;
        }
        unsigned here = gsl_ran_binomial(rng, 1.0 - q, (unsigned)left);
        (*count)[++top] = here;
        left -= here;
    }
    return top;
}

/* The length of numpy's arange(start, stop, step): ceil((stop - start) / step). */
static size_t arange_length(double start, double stop, double step)
{
    double n = ceil((stop - start) / step);
    return n > 0.0 ? (size_t)n : 0;
}


/* The smallest and largest of n >= 2 finite magnitudes that differ. */
static int magnitude_range(const double *m, size_t n, const char *what, double *lo, double *hi, bk_error *err)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(m[i]))
            return BK_FAIL(err, BK_ERR_INVALID, "%s: magnitude %zu is %g: must be finite", what, i, m[i]);
        *lo = fmin(*lo, m[i]);
        *hi = fmax(*hi, m[i]);
    }
    if (n < 2 || !(*hi > *lo))
        return BK_FAIL(err, BK_ERR_INVALID, "%s: %zu magnitudes: needs at least 2 that differ", what, n);
    return BK_OK;
}

int bk_mc_b_stability(const double *m, size_t n, double dm, double range, bk_mc_stability *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(isfinite(dm) && dm > 0.0) || !(isfinite(range) && range >= dm))
        return BK_FAIL(err, BK_ERR_INVALID, "Mc by b-stability: dm = %g, range = %g: allowed 0 < dm <= range", dm,
                       range);
    double lo, hi;
    int rc = magnitude_range(m, n, "Mc by b-stability", &lo, &hi, err);
    if (rc != BK_OK)
        return rc;
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
        double mc = bk_stats_to_bin(lo + (double)c * dm, dm);
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
                   out->n_tested, bk_stats_to_bin(lo, dm), range);
}

int bk_gr_ks_distance(const double *m, size_t n, double mc, double dm, double b, double *d, bk_error *err)
{
    long *k = malloc((n ? n : 1) * sizeof *k);
    if (!k)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu magnitudes", n);
    size_t count = 0;
    for (size_t i = 0; i < n; ++i)
        if (m[i] >= mc - 0.5 * dm)
            k[count++] = (long)floor((m[i] - mc) / dm + 0.5 + 1e-9);
    if (count == 0 || !(b > 0.0) || !(dm > 0.0)) {
        free(k);
        return BK_FAIL(err, BK_ERR_INVALID, "GR KS distance: %zu magnitudes at or above Mc = %g, b = %g, dm = %g",
                       count, mc, b, dm);
    }
    *d = bk_gr_distance(k, count, pow(10.0, -b * dm));
    free(k);
    return BK_OK;
}

int bk_mc_ks(const double *m, size_t n, double dm, double p_pass, size_t n_synthetic, unsigned long seed,
             bk_mc_ks_result *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(isfinite(dm) && dm > 0.0) || !(p_pass > 0.0 && p_pass < 1.0) || n_synthetic < 1 ||
        n_synthetic > BK_BOOTSTRAP_MAX)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "Mc by the KS method: dm = %g, pass level %g, %zu synthetic samples: allowed dm > 0, 0 < level "
                       "< 1, 1 .. %d samples",
                       dm, p_pass, n_synthetic, BK_BOOTSTRAP_MAX);
    double lo, hi;
    int status = magnitude_range(m, n, "Mc by the KS method", &lo, &hi, err);
    if (status != BK_OK)
        return status;
    if (n > UINT_MAX)
        return BK_FAIL(err, BK_ERR_INVALID, "Mc by the KS method: %zu magnitudes: at most %u", n, UINT_MAX);
    size_t cap = 64;
    long *k = malloc(n * sizeof *k);
    size_t *synthetic = malloc(cap * sizeof *synthetic);
    gsl_rng *rng = bk_stats_rng(seed);
    if (!k || !synthetic || !rng) {
        free(k);
        free(synthetic);
        if (rng)
            gsl_rng_free(rng);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu magnitudes", n);
    }
    size_t candidates = arange_length(lo, hi, dm);
    int rc = BK_FAIL(err, BK_ERR_INVALID,
                     "Mc by the KS method: no candidate from %g to %g passes (p >= %g against its own GR fit)",
                     bk_stats_to_bin(lo, dm), bk_stats_to_bin(hi, dm), p_pass);
    for (size_t c = 0; c < candidates; ++c) {
        double mc = bk_stats_to_bin(lo + (double)c * dm, dm);
        bk_b_estimate fit;
        bk_error ignored = {0};
        if (bk_b_tinti(m, n, mc, dm, &fit, &ignored) != BK_OK)
            continue;
        size_t count = 0;
        for (size_t i = 0; i < n; ++i)
            if (m[i] >= mc - 0.5 * dm)
                k[count++] = (long)floor((m[i] - mc) / dm + 0.5 + 1e-9);
        if (count < 2)
            continue;
        double q = pow(10.0, -fit.b * dm), d = bk_gr_distance(k, count, q);
        /* A slope this flat spreads a sample over ~1e9 bins: no law to test against. */
        if (!(q < 1.0 - 1e-9))
            continue;
        size_t at_least = 0;
        for (size_t s = 0; s < n_synthetic; ++s) {
            long top = draw_counts(rng, count, q, &synthetic, &cap);
            if (top < 0) {
                rc = BK_FAIL(err, BK_ERR_NOMEM, "Mc by the KS method: out of memory for a synthetic sample");
                goto done;
            }
            at_least += bk_gr_distance_counts(synthetic, top, count, q) >= d;
        }
        out->n_tested = c + 1;
        out->mc = mc;
        out->b = fit.b;
        out->d = d;
        out->p = (double)at_least / (double)n_synthetic;
        out->n = count;
        if (out->p >= p_pass) {
            out->found = 1;
            rc = BK_OK;
            break;
        }
    }
done:
    free(k);
    free(synthetic);
    gsl_rng_free(rng);
    return rc;
}
