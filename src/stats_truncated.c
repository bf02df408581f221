/* The Gutenberg-Richter law on [Mc, Mu]: its maximum-likelihood b, its goodness of fit and
 * the scan for the largest Mu it describes (the estimators, the two distances of the fit
 * test and the references are in include/bksim/stats_truncated.h).
 *
 * Everything works on the histogram of bin offsets j = 0..J: the likelihood depends on the
 * sample only through n and sum j, both distances only through the counts, and a
 * synthetic sample is drawn as counts.  So the bootstrap costs O(J) per sample whatever the
 * catalog's size, and the scan bins the magnitudes once. */
#include "bksim/stats_truncated.h"
#include "stats_impl.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#define LOG10_E 0.43429448190325182765
#define LN_10 2.30258509299404568402
/* Below this |(J + 1) theta| the mean and variance are taken from their Taylor series: the
 * closed forms subtract two terms of size 1/theta there.  At 0.03 the series' first omitted
 * term is below 1e-16 of the value and the closed forms lose at most 4 digits (the variance;
 * 2 for the mean). */
#define SERIES_LIMIT 0.03
/* A synthetic distance this close to the sample's (relative, for the deviance) counts as a
 * tie: the same counts give the same bits, but other counts at the same true distance may
 * round differently, and a fit that reproduces its counts has distances of rounding size. */
#define TIE_TOLERANCE 1e-12

/* E_theta[j] of the law P(j) ~ e^(theta j), j = 0..J, J1 = J + 1: u(theta) - J1 u(J1 theta)
 * with u(x) = e^x / (1 - e^x) = 1 / expm1(-x), whose poles at 0 cancel.  The series is
 * u(x) = -1/x - 1/2 - x/12 + x^3/720 - x^5/30240 + ... (Bernoulli numbers). */
static double mean_offset(double theta, double j1)
{
    double x = j1 * theta;
    if (fabs(x) < SERIES_LIMIT) {
        double j2 = j1 * j1, t2 = theta * theta;
        return 0.5 * (j1 - 1.0) + theta * (j2 - 1.0) / 12.0 - theta * t2 * (j2 * j2 - 1.0) / 720.0 +
               theta * t2 * t2 * (j2 * j2 * j2 - 1.0) / 30240.0;
    }
    return 1.0 / expm1(-theta) - j1 / expm1(-x);
}

/* Var_theta[j] = d E / d theta = u'(theta) - J1^2 u'(J1 theta), u'(x) = 1 / (4 sinh^2(x/2))
 * = 1/x^2 - 1/12 + x^2/240 - x^4/6048 + x^6/172800 - ... */
static double var_offset(double theta, double j1)
{
    double x = j1 * theta;
    if (fabs(x) < SERIES_LIMIT) {
        double j2 = j1 * j1, t2 = theta * theta, j4 = j2 * j2;
        return (j2 - 1.0) / 12.0 - t2 * (j4 - 1.0) / 240.0 + t2 * t2 * (j4 * j2 - 1.0) / 6048.0 -
               t2 * t2 * t2 * (j4 * j4 - 1.0) / 172800.0;
    }
    double s = sinh(0.5 * theta), sx = sinh(0.5 * x);
    return 0.25 / (s * s) - 0.25 * j1 * j1 / (sx * sx);
}

/* theta = ln q of the law whose mean offset is jbar, 0 < jbar < J.  E is increasing and
 * E_{-theta} = J - E_theta (the law read from the top bin down), so a mean above J/2 is
 * solved as J - jbar and reflected, and the root is negative.  There the untruncated root
 * ln(jbar / (1 + jbar)) lies at or left of it (truncation only lowers the mean at a given
 * theta), which starts a Newton iteration kept inside a bisection bracket. */
static double solve_theta(double jbar, double j)
{
    if (jbar == 0.5 * j)
        return 0.0;
    int reflect = jbar > 0.5 * j;
    double target = reflect ? j - jbar : jbar, j1 = j + 1.0;
    double x = log(target) - log1p(target);
    double lo = x - 1.0, hi = 0.0;
    for (int it = 0; it < 200; ++it) {
        double f = mean_offset(x, j1) - target;
        if (f == 0.0)
            break;
        if (f < 0.0)
            lo = x;
        else
            hi = x;
        double next = x - f / var_offset(x, j1);
        if (!(next > lo && next < hi))
            next = 0.5 * (lo + hi);
        int done = fabs(next - x) <= 2.0 * DBL_EPSILON * fabs(x) || hi - lo <= 2.0 * DBL_EPSILON * fabs(lo);
        x = next;
        if (done)
            break;
    }
    return reflect ? -x : x;
}

/* The law's distribution function at j < J: (1 - q^(j+1)) / (1 - q^(J+1)), written for q > 1
 * from the top so that nothing overflows. */
static double law_cdf(double theta, double j, double j1)
{
    if (theta < 0.0)
        return expm1((j + 1.0) * theta) / expm1(j1 * theta);
    if (theta > 0.0)
        return 1.0 - expm1((j + 1.0 - j1) * theta) / expm1(-j1 * theta);
    return (j + 1.0) / j1;
}

/* ln P(0), the bottom bin's probability, without overflow for q > 1. */
static double log_p0(double theta, double j1)
{
    if (theta < 0.0)
        return log(-expm1(theta)) - log(-expm1(j1 * theta));
    if (theta > 0.0)
        return log(expm1(theta)) - j1 * theta - log(-expm1(-j1 * theta));
    return -log(j1);
}

/* The two distances between counts c[0..J] of n offsets and the law of theta: Kolmogorov-
 * Smirnov's D (at J both distribution functions are 1) and the deviance G; ln P(j) is
 * ln P(0) + theta j, so a bin far down a steep law has no underflowing probability. */
static void distances(const unsigned *c, size_t j_top, double n, double theta, double *d, double *g)
{
    double j1 = (double)j_top + 1.0, lp0 = log_p0(theta, j1), ln_n = log(n);
    double cumulative = 0.0, dist = 0.0, dev = 0.0;
    for (size_t j = 0; j <= j_top; ++j) {
        if (c[j] > 0)
            dev += (double)c[j] * (log((double)c[j]) - ln_n - (lp0 + theta * (double)j));
        if (j < j_top) {
            cumulative += (double)c[j];
            dist = fmax(dist, fabs(cumulative / n - law_cdf(theta, (double)j, j1)));
        }
    }
    *d = dist;
    *g = fmax(2.0 * dev, 0.0); /* >= 0 exactly; rounding can leave -1e-13 at a perfect fit */
}

/* The distances between counts and their own fit.  All in the bottom (or top) bin is fitted
 * by q -> 0 (infinity), a law that puts everything there: both 0. */
static void refit_distances(const unsigned *c, size_t j_top, unsigned n, double *d, double *g)
{
    uint64_t sum = 0;
    for (size_t j = 1; j <= j_top; ++j)
        sum += (uint64_t)j * c[j];
    if (sum == 0 || sum == (uint64_t)j_top * n) {
        *d = *g = 0.0;
        return;
    }
    double theta = solve_theta((double)sum / (double)n, (double)j_top);
    distances(c, j_top, (double)n, theta, d, g);
}

/* out->d and out->g against n_synthetic samples of n offsets from the law of theta, each
 * refitted: the two p-values and their combination.  w and c hold J + 1 entries each. */
static void bootstrap(size_t j_top, unsigned n, double theta, size_t n_synthetic, gsl_rng *rng, double *w,
                      unsigned *c, bk_truncated_gof *out)
{
    /* Unnormalised weights from the likelier end (GSL normalises), so none overflows. */
    double ref = theta > 0.0 ? (double)j_top : 0.0;
    for (size_t j = 0; j <= j_top; ++j)
        w[j] = exp(theta * ((double)j - ref));
    size_t beyond_d = 0, beyond_g = 0;
    for (size_t s = 0; s < n_synthetic; ++s) {
        gsl_ran_multinomial(rng, j_top + 1, n, w, c);
        double d, g;
        refit_distances(c, j_top, n, &d, &g);
        beyond_d += d >= out->d - TIE_TOLERANCE;
        beyond_g += g >= out->g - TIE_TOLERANCE * fmax(1.0, out->g);
    }
    out->n_synthetic = n_synthetic;
    out->p_ks = (double)beyond_d / (double)n_synthetic;
    out->p_g = (double)beyond_g / (double)n_synthetic;
    out->p = fmin(1.0, 2.0 * fmin(out->p_ks, out->p_g));
}

/* The estimate of n offsets in bins k_mc..k_mc + J with offset sum `sum`. */
static void fill_estimate(bk_b_truncated_estimate *out, long k_mc, size_t j_top, double dm, size_t n,
                          uint64_t sum, size_t n_below, size_t n_above)
{
    double j = (double)j_top, j1 = j + 1.0, nd = (double)n;
    double jbar = (double)sum / nd;
    double theta = solve_theta(jbar, j);
    memset(out, 0, sizeof *out);
    out->mc = (double)k_mc * dm;
    out->mu = (double)(k_mc + (long)j_top) * dm;
    out->dm = dm;
    out->n_bins = j_top + 1;
    out->n = n;
    out->n_below = n_below;
    out->n_above = n_above;
    out->mean = out->mc + jbar * dm;
    out->b = theta == 0.0 ? 0.0 : -theta / (dm * LN_10); /* not -0 for an even split */
    out->sigma = 1.0 / (dm * LN_10 * sqrt(nd * var_offset(theta, j1)));
    out->a_bin = log10(nd) + log_p0(theta, j1) * LOG10_E + out->b * out->mc;
    out->a = out->b > 0.0 ? out->a_bin - log10(-expm1(theta)) : NAN;
}

static int check_dm(double dm, bk_error *err)
{
    if (!(isfinite(dm) && dm > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "magnitude bin width dm = %g: must be finite and > 0", dm);
    return BK_OK;
}

/* The bin of Mc or Mu, which must be a bin centre (as bk_b_value's Mc). */
static int centre_bin(double x, double dm, const char *name, long *k, bk_error *err)
{
    if (!isfinite(x))
        return BK_FAIL(err, BK_ERR_INVALID, "%s = %g: must be finite", name, x);
    if (!bk_stats_centre_bin(x, dm, k))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%s = %g is not a bin centre: it must be a multiple of the bin width dm = %g", name, x, dm);
    return BK_OK;
}

/* Mc and Mu as bin indices, Mu above Mc by 1 .. BK_MFD_MAX_BINS - 1 bins. */
static int range_bins(double mc, double mu, double dm, long *k_mc, long *k_mu, bk_error *err)
{
    int rc;
    if ((rc = check_dm(dm, err)) != BK_OK || (rc = centre_bin(mc, dm, "Mc", k_mc, err)) != BK_OK ||
        (rc = centre_bin(mu, dm, "Mu", k_mu, err)) != BK_OK)
        return rc;
    if (*k_mu <= *k_mc)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "Mu = %g: must be above Mc = %g by at least one bin of dm = %g (the truncated law needs "
                       "2 bins or more)",
                       mu, mc, dm);
    if (*k_mu - *k_mc >= BK_MFD_MAX_BINS)
        return BK_FAIL(err, BK_ERR_INVALID, "Mc = %g to Mu = %g in bins of dm = %g make %ld bins: at most %ld", mc,
                       mu, dm, *k_mu - *k_mc + 1, BK_MFD_MAX_BINS);
    return BK_OK;
}

static int magnitude_bin(const double *m, size_t i, double dm, long *k, bk_error *err)
{
    if (!isfinite(m[i]))
        return BK_FAIL(err, BK_ERR_INVALID, "magnitude %zu is %g: must be finite", i, m[i]);
    return bk_mag_bin(m[i], dm, k, err);
}

int bk_b_truncated(const double *m, size_t n, double mc, double mu, double dm, bk_b_truncated_estimate *out,
                   bk_error *err)
{
    memset(out, 0, sizeof *out);
    long k_mc = 0, k_mu = 0;
    int rc = range_bins(mc, mu, dm, &k_mc, &k_mu, err);
    if (rc != BK_OK)
        return rc;
    size_t count = 0, below = 0, above = 0;
    uint64_t sum = 0;
    long lowest = k_mu, highest = k_mc;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        if ((rc = magnitude_bin(m, i, dm, &k, err)) != BK_OK)
            return rc;
        if (k < k_mc)
            ++below;
        else if (k > k_mu)
            ++above;
        else {
            ++count;
            sum += (uint64_t)(k - k_mc);
            lowest = k < lowest ? k : lowest;
            highest = k > highest ? k : highest;
        }
    }
    double mc_c = (double)k_mc * dm, mu_c = (double)k_mu * dm;
    if (count < BK_B_MIN_EVENTS)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%zu magnitude%s in Mc = %g .. Mu = %g (bins of dm = %g): the truncated b-value needs at "
                       "least %d",
                       count, count == 1 ? "" : "s", mc_c, mu_c, dm, BK_B_MIN_EVENTS);
    if (lowest == highest)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "all %zu magnitudes in Mc = %g .. Mu = %g fall in one bin of dm = %g: no spread to estimate "
                       "a slope from",
                       count, mc_c, mu_c, dm);
    fill_estimate(out, k_mc, (size_t)(k_mu - k_mc), dm, count, sum, below, above);
    return BK_OK;
}

static int check_synthetic(size_t n_synthetic, size_t least, bk_error *err)
{
    if (n_synthetic < least || n_synthetic > BK_BOOTSTRAP_MAX)
        return BK_FAIL(err, BK_ERR_INVALID, "synthetic samples %zu: allowed %zu .. %d", n_synthetic, least,
                       BK_BOOTSTRAP_MAX);
    return BK_OK;
}

/* The same theta from a fit wherever it is tested, so that the scan's p for a Mu is
 * bk_b_truncated_gof's to the bit. */
static double fit_theta(const bk_b_truncated_estimate *fit)
{
    return -fit->b * fit->dm * LN_10;
}

int bk_b_truncated_gof(const double *m, size_t n, const bk_b_truncated_estimate *fit, size_t n_synthetic,
                       unsigned long seed, bk_truncated_gof *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_synthetic(n_synthetic, 1, err);
    if (rc != BK_OK)
        return rc;
    long k_mc = 0, k_mu = 0;
    if ((rc = range_bins(fit->mc, fit->mu, fit->dm, &k_mc, &k_mu, err)) != BK_OK)
        return rc;
    if (!isfinite(fit->b))
        return BK_FAIL(err, BK_ERR_INVALID, "truncated GR fit with b = %g: must be finite", fit->b);
    size_t j_top = (size_t)(k_mu - k_mc);
    unsigned *c = calloc(2 * (j_top + 1), sizeof *c);
    double *w = malloc((j_top + 1) * sizeof *w);
    gsl_rng *rng = bk_stats_rng(seed);
    if (!c || !w || !rng) {
        rc = BK_FAIL(err, BK_ERR_NOMEM, "out of memory for a bootstrap over %zu bins", j_top + 1);
        goto done;
    }
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        if ((rc = magnitude_bin(m, i, fit->dm, &k, err)) != BK_OK)
            goto done;
        if (k >= k_mc && k <= k_mu) {
            if (count == UINT_MAX) {
                rc = BK_FAIL(err, BK_ERR_INVALID, "more than %u magnitudes in Mc = %g .. Mu = %g: too many to test",
                             UINT_MAX, fit->mc, fit->mu);
                goto done;
            }
            ++count;
            ++c[k - k_mc];
        }
    }
    if (count != fit->n || count < 2) {
        rc = BK_FAIL(err, BK_ERR_INVALID,
                     "the fit describes %zu magnitudes in Mc = %g .. Mu = %g and the sample has %zu there: test a "
                     "fit (of at least 2) on the magnitudes it was fitted to",
                     fit->n, fit->mc, fit->mu, count);
        goto done;
    }
    double theta = fit_theta(fit);
    out->n = count;
    distances(c, j_top, (double)count, theta, &out->d, &out->g);
    bootstrap(j_top, (unsigned)count, theta, n_synthetic, rng, w, c + j_top + 1, out);
    rc = BK_OK;
done:
    free(c);
    free(w);
    if (rng)
        gsl_rng_free(rng);
    return rc;
}

int bk_gr_truncation_scan(const double *m, size_t n, double mc, double dm, size_t min_bins, size_t n_synthetic,
                          unsigned long seed, bk_gr_truncation *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    long k_mc = 0;
    int rc;
    if ((rc = check_dm(dm, err)) != BK_OK || (rc = centre_bin(mc, dm, "Mc", &k_mc, err)) != BK_OK ||
        (rc = check_synthetic(n_synthetic, BK_TRUNCATED_MIN_SYNTHETIC, err)) != BK_OK)
        return rc;
    if (min_bins < BK_TRUNCATED_MIN_BINS || min_bins > (size_t)BK_MFD_MAX_BINS)
        return BK_FAIL(err, BK_ERR_INVALID, "truncation scan: minimum range of %zu bins: allowed %d .. %ld",
                       min_bins, BK_TRUNCATED_MIN_BINS, BK_MFD_MAX_BINS);
    size_t below = 0, at_or_above = 0;
    long k_top = k_mc;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        if ((rc = magnitude_bin(m, i, dm, &k, err)) != BK_OK)
            return rc;
        if (k < k_mc)
            ++below;
        else {
            ++at_or_above;
            k_top = k > k_top ? k : k_top;
        }
    }
    double mc_c = (double)k_mc * dm;
    if (at_or_above == 0)
        return BK_FAIL(err, BK_ERR_INVALID, "truncation scan: no magnitude at or above Mc = %g", mc_c);
    if ((size_t)(k_top - k_mc) + 1 < min_bins)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "truncation scan: the magnitudes at or above Mc = %g reach %g, %ld bin%s of dm = %g: the scan "
                       "needs at least %zu",
                       mc_c, (double)k_top * dm, k_top - k_mc + 1, k_top == k_mc ? "" : "s", dm, min_bins);
    if (k_top - k_mc >= BK_MFD_MAX_BINS)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "truncation scan: Mc = %g to %g in bins of dm = %g make %ld bins: at most %ld", mc_c,
                       (double)k_top * dm, dm, k_top - k_mc + 1, BK_MFD_MAX_BINS);
    if (at_or_above > UINT_MAX)
        return BK_FAIL(err, BK_ERR_INVALID, "truncation scan: %zu magnitudes at or above Mc = %g: at most %u",
                       at_or_above, mc_c, UINT_MAX);
    size_t bins = (size_t)(k_top - k_mc) + 1;
    unsigned *c = calloc(2 * bins, sizeof *c);
    double *w = malloc(bins * sizeof *w);
    gsl_rng *rng = bk_stats_rng(seed);
    if (!c || !w || !rng) {
        rc = BK_FAIL(err, BK_ERR_NOMEM, "out of memory for a truncation scan over %zu bins", bins);
        goto done;
    }
    uint64_t sum = 0;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        bk_mag_bin(m[i], dm, &k, NULL);
        if (k >= k_mc) {
            ++c[k - k_mc];
            sum += (uint64_t)(k - k_mc);
        }
    }
    out->mc = mc_c;
    out->dm = dm;
    out->m_top = (double)k_top * dm;
    out->gof.p = -1.0; /* below any p: the first candidate tested becomes the best */
    size_t count = at_or_above;
    /* Down from the top bin, the bins above the candidate taken off the running count and
     * offset sum as the scan passes them. */
    for (size_t j_top = bins - 1; j_top + 1 >= min_bins; --j_top) {
        if (c[j_top] > 0 && count >= BK_B_MIN_EVENTS && c[j_top] < count) {
            bk_b_truncated_estimate fit;
            fill_estimate(&fit, k_mc, j_top, dm, count, sum, below, at_or_above - count);
            double theta = fit_theta(&fit);
            bk_truncated_gof gof = {.n = count};
            distances(c, j_top, (double)count, theta, &gof.d, &gof.g);
            gsl_rng_set(rng, seed);
            bootstrap(j_top, (unsigned)count, theta, n_synthetic, rng, w, c + bins, &gof);
            ++out->n_tested;
            if (gof.p > out->gof.p) {
                out->fit = fit;
                out->gof = gof;
            }
            if (gof.p >= BK_GOF_LEVEL) {
                out->found = 1;
                out->fit = fit;
                out->gof = gof;
                break;
            }
        }
        count -= c[j_top];
        sum -= (uint64_t)j_top * c[j_top];
        if (count < BK_B_MIN_EVENTS || j_top == 0)
            break; /* every lower range has fewer */
    }
    if (out->n_tested == 0) {
        out->gof.p = 0.0;
        rc = BK_FAIL(err, BK_ERR_INVALID,
                     "truncation scan: no range from Mc = %g of at least %zu bins holds %d magnitudes in two bins or "
                     "more",
                     mc_c, min_bins, BK_B_MIN_EVENTS);
        goto done;
    }
    rc = BK_OK;
done:
    free(c);
    free(w);
    if (rng)
        gsl_rng_free(rng);
    return rc;
}
