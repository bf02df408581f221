/* Whether a fit describes its sample, and how well its parameters are known: the
 * Kolmogorov-Smirnov distance between a sample and the law fitted to it, with a
 * parametric-bootstrap p-value (Clauset, Shalizi & Newman 2009, section 4.1: synthetic
 * samples drawn from the fitted law, each refitted, their distances to their own fits
 * counted against the sample's), for the binned Gutenberg-Richter law above Mc and for the
 * potency power law; and bootstrap standard errors of b and Mc (the catalog resampled with
 * replacement, Mc and b estimated again on each resample).  Every draw comes from GSL's
 * MT19937 seeded by the caller: the same seed gives the same p-values and errors. */
#include "bksim/stats.h"
#include "stats_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_rng.h>

#define LOG10_E 0.43429448190325182765

/* The binned magnitudes at or above Mc as bin offsets k = 0, 1, ... from it. */
static int offsets_above(const double *m, size_t n, double mc, double dm, long **out, size_t *count,
                         bk_error *err)
{
    long k_mc = (long)floor(mc / dm + 0.5);
    long *k = malloc((n ? n : 1) * sizeof *k);
    if (!k)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu magnitudes", n);
    size_t c = 0;
    for (size_t i = 0; i < n; ++i) {
        long bin = 0;
        int rc = bk_mag_bin(m[i], dm, &bin, err);
        if (rc != BK_OK) {
            free(k);
            return rc;
        }
        if (bin >= k_mc)
            k[c++] = bin - k_mc;
    }
    *out = k;
    *count = c;
    return BK_OK;
}

gsl_rng *bk_stats_rng(unsigned long seed)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (rng)
        gsl_rng_set(rng, seed);
    return rng;
}

static int compare_longs(const void *pa, const void *pb)
{
    long a = *(const long *)pa, b = *(const long *)pb;
    return (a > b) - (a < b);
}

/* The binned GR law above Mc is geometric in the bin offset: P(k) = (1 - q) q^k with
 * q = 10^(-b dm), CDF 1 - q^(k + 1) (stats_impl.h). */
double bk_gr_distance_counts(const size_t *count, long top, size_t n, double q)
{
    double d = 0.0;
    size_t below = 0;
    for (long bin = 0; bin <= top; ++bin) {
        below += count[bin];
        double empirical = (double)below / (double)n, model = 1.0 - pow(q, (double)(bin + 1));
        d = fmax(d, fabs(empirical - model));
    }
    return d;
}

/* The empirical CDF comes from a count per offset (offsets span a few dozen bins): sorting
 * every synthetic sample of a bootstrap cost most of a long catalog's report.  A span too
 * long to count falls back to sorting a copy. */
double bk_gr_distance(const long *k, size_t n, double q)
{
    long top = 0;
    for (size_t i = 0; i < n; ++i)
        top = k[i] > top ? k[i] : top;
    size_t *count = (size_t)top < 16 * n + 1024 ? calloc((size_t)top + 1, sizeof *count) : NULL;
    if (count) {
        for (size_t i = 0; i < n; ++i)
            ++count[k[i]];
        double d = bk_gr_distance_counts(count, top, n, q);
        free(count);
        return d;
    }
    long *sorted = malloc((n ? n : 1) * sizeof *sorted);
    if (!sorted)
        return NAN;
    memcpy(sorted, k, n * sizeof *sorted);
    qsort(sorted, n, sizeof *sorted, compare_longs);
    double d = 0.0;
    size_t i = 0;
    for (long bin = 0; i < n; ++bin) {
        while (i < n && sorted[i] <= bin)
            ++i;
        double empirical = (double)i / (double)n, model = 1.0 - pow(q, (double)(bin + 1));
        d = fmax(d, fabs(empirical - model));
    }
    free(sorted);
    return d;
}

/* b of bin offsets by the Aki-Utsu estimator (bk_b_value's), as q = 10^(-b dm). */
static double fitted_q(const long *k, size_t n, double dm)
{
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i)
        sum += (double)k[i];
    double b = LOG10_E / ((sum / (double)n + 0.5) * dm);
    return pow(10.0, -b * dm);
}

static int check_synthetic(size_t n_synthetic, bk_error *err)
{
    if (n_synthetic < 1 || n_synthetic > BK_BOOTSTRAP_MAX)
        return BK_FAIL(err, BK_ERR_INVALID, "bootstrap samples %zu: allowed 1 .. %d", n_synthetic,
                       BK_BOOTSTRAP_MAX);
    return BK_OK;
}

int bk_gr_gof(const double *m, size_t n, const bk_b_estimate *fit, size_t n_synthetic, unsigned long seed,
              bk_gof *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_synthetic(n_synthetic, err);
    if (rc != BK_OK)
        return rc;
    long *k = NULL;
    size_t count = 0;
    if ((rc = offsets_above(m, n, fit->mc, fit->dm, &k, &count, err)) != BK_OK)
        return rc;
    if (count < 2) {
        free(k);
        return BK_FAIL(err, BK_ERR_INVALID, "%zu magnitudes at or above Mc = %g: a fit needs at least 2", count,
                       fit->mc);
    }
    long *synthetic = malloc(count * sizeof *synthetic);
    gsl_rng *rng = bk_stats_rng(seed);
    if (!synthetic || !rng) {
        free(k);
        free(synthetic);
        if (rng)
            gsl_rng_free(rng);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for a bootstrap of %zu magnitudes", count);
    }
    double q = pow(10.0, -fit->b * fit->dm);
    out->n = count;
    out->d = bk_gr_distance(k, count, q);
    double log_q = log(q);
    size_t at_least = 0;
    for (size_t s = 0; s < n_synthetic; ++s) {
        for (size_t i = 0; i < count; ++i)
            synthetic[i] = bk_stats_draw_offset(rng, log_q);
        double d = bk_gr_distance(synthetic, count, fitted_q(synthetic, count, fit->dm));
        at_least += d >= out->d;
    }
    out->p = (double)at_least / (double)n_synthetic;
    out->n_synthetic = n_synthetic;
    free(k);
    free(synthetic);
    gsl_rng_free(rng);
    return BK_OK;
}

/* D between sorted values x >= x_min and the power law of density exponent alpha. */
static double power_law_distance(const double *x, size_t n, double x_min, double alpha)
{
    double d = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double model = 1.0 - pow(x[i] / x_min, 1.0 - alpha);
        d = fmax(d, fmax(fabs((double)(i + 1) / (double)n - model), fabs(model - (double)i / (double)n)));
    }
    return d;
}

static int compare_doubles(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

int bk_power_law_gof(const double *x, size_t n, const bk_power_law *fit, size_t n_synthetic,
                     unsigned long seed, bk_gof *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_synthetic(n_synthetic, err);
    if (rc != BK_OK)
        return rc;
    double *above = malloc((n ? n : 1) * sizeof *above), *synthetic = malloc((n ? n : 1) * sizeof *synthetic);
    gsl_rng *rng = bk_stats_rng(seed);
    if (!above || !synthetic || !rng) {
        free(above);
        free(synthetic);
        if (rng)
            gsl_rng_free(rng);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for a bootstrap of %zu values", n);
    }
    size_t count = 0;
    for (size_t i = 0; i < n; ++i)
        if (x[i] >= fit->x_min)
            above[count++] = x[i];
    if (count < 2 || !(fit->alpha > 1.0)) {
        free(above);
        free(synthetic);
        gsl_rng_free(rng);
        return BK_FAIL(err, BK_ERR_INVALID, "%zu values at or above %g with exponent %g: a fit needs at least 2 "
                       "and an exponent > 1", count, fit->x_min, fit->alpha);
    }
    qsort(above, count, sizeof *above, compare_doubles);
    out->n = count;
    out->d = power_law_distance(above, count, fit->x_min, fit->alpha);
    size_t at_least = 0;
    for (size_t s = 0; s < n_synthetic; ++s) {
        double logs = 0.0;
        for (size_t i = 0; i < count; ++i) {
            synthetic[i] = fit->x_min * pow(gsl_rng_uniform_pos(rng), -1.0 / (fit->alpha - 1.0));
            logs += log(synthetic[i] / fit->x_min);
        }
        double alpha = 1.0 + (double)count / logs;
        qsort(synthetic, count, sizeof *synthetic, compare_doubles);
        at_least += power_law_distance(synthetic, count, fit->x_min, alpha) >= out->d;
    }
    out->p = (double)at_least / (double)n_synthetic;
    out->n_synthetic = n_synthetic;
    free(above);
    free(synthetic);
    gsl_rng_free(rng);
    return BK_OK;
}

int bk_b_bootstrap(const double *m, size_t n, const bk_b_options *opt, size_t n_resamples, unsigned long seed,
                   bk_b_spread *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_synthetic(n_resamples, err);
    if (rc != BK_OK)
        return rc;
    if (n < 2)
        return BK_FAIL(err, BK_ERR_INVALID, "%zu magnitudes: a bootstrap needs at least 2", n);
    double *resample = malloc(n * sizeof *resample);
    gsl_rng *rng = bk_stats_rng(seed);
    if (!resample || !rng) {
        free(resample);
        if (rng)
            gsl_rng_free(rng);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for a bootstrap of %zu magnitudes", n);
    }
    /* Welford: the spread of the estimates without keeping them. */
    double b_mean = 0.0, b_m2 = 0.0, mc_mean = 0.0, mc_m2 = 0.0;
    size_t used = 0;
    bk_error ignored = {0};
    for (size_t s = 0; s < n_resamples; ++s) {
        for (size_t i = 0; i < n; ++i)
            resample[i] = m[gsl_rng_uniform_int(rng, n)];
        double mc = opt->mc;
        if (opt->mc_auto) {
            bk_mfd mfd;
            if (bk_mfd_build(resample, n, opt->dm, &mfd, &ignored) != BK_OK)
                continue;
            rc = bk_mc_maxc(&mfd, opt->mc_correction, &mc, &ignored);
            bk_mfd_free(&mfd);
            if (rc != BK_OK)
                continue;
        }
        bk_b_estimate est;
        if (bk_b_value(resample, n, mc, opt->dm, &est, &ignored) != BK_OK)
            continue; /* a resample without the spread or the count a b-value needs */
        ++used;
        double db = est.b - b_mean, dmc = mc - mc_mean;
        b_mean += db / (double)used;
        mc_mean += dmc / (double)used;
        b_m2 += db * (est.b - b_mean);
        mc_m2 += dmc * (mc - mc_mean);
    }
    free(resample);
    gsl_rng_free(rng);
    out->n_resamples = n_resamples;
    out->n_used = used;
    if (used < 2)
        return BK_FAIL(err, BK_ERR_INVALID, "%zu of %zu resamples gave a b-value: a spread needs at least 2",
                       used, n_resamples);
    out->b_sigma = sqrt(b_m2 / (double)(used - 1));
    out->mc_sigma = opt->mc_auto ? sqrt(mc_m2 / (double)(used - 1)) : 0.0;
    return BK_OK;
}
