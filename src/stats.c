/* Catalog statistics: binning, the magnitude-frequency distribution, Mc, the b-value, the
 * potency exponent, event sizes, recurrence intervals and the two-sample KS test.  The
 * estimators and their references are in include/bksim/stats.h. */
#include "bksim/stats.h"
#include "stats_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LOG10_E 0.43429448190325182765
#define LN_10 2.30258509299404568402
#define PI 3.14159265358979323846
/* Beyond this |m/dm| a bin index no longer has a unit step in a double. */
#define MAX_BIN_INDEX 1e15

static int compare_doubles(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

static int check_dm(double dm, bk_error *err)
{
    if (!(isfinite(dm) && dm > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "magnitude bin width dm = %g: must be finite and > 0",
                       dm);
    return BK_OK;
}

int bk_mag_bin(double m, double dm, long *bin, bk_error *err)
{
    int rc = check_dm(dm, err);
    if (rc != BK_OK)
        return rc;
    if (!isfinite(m))
        return BK_FAIL(err, BK_ERR_INVALID, "magnitude %g is not finite", m);
    double k = floor(m / dm + 0.5 + BK_MAG_BIN_EPS);
    if (!(fabs(k) <= MAX_BIN_INDEX))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "magnitude %g is %g bins of dm = %g from 0: at most 1e15 bins allowed", m,
                       k, dm);
    *bin = (long)k;
    return BK_OK;
}

/* ------------------------------------------------------------------- MFD --- */

double bk_mfd_centre(const bk_mfd *mfd, size_t i)
{
    return (double)(mfd->first_bin + (long)i) * mfd->dm;
}

void bk_mfd_free(bk_mfd *mfd)
{
    if (!mfd)
        return;
    free(mfd->incremental);
    free(mfd->cumulative);
    memset(mfd, 0, sizeof *mfd);
}

int bk_mfd_build(const double *m, size_t n, double dm, bk_mfd *mfd, bk_error *err)
{
    memset(mfd, 0, sizeof *mfd);
    int rc = check_dm(dm, err);
    if (rc != BK_OK)
        return rc;
    if (n == 0)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "the magnitude-frequency distribution needs at least 1 magnitude, got 0");
    long lo = 0, hi = 0;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        if (!isfinite(m[i]))
            return BK_FAIL(err, BK_ERR_INVALID, "magnitude %zu is %g: must be finite", i, m[i]);
        if ((rc = bk_mag_bin(m[i], dm, &k, err)) != BK_OK)
            return rc;
        if (i == 0 || k < lo)
            lo = k;
        if (i == 0 || k > hi)
            hi = k;
    }
    if (hi - lo >= BK_MFD_MAX_BINS)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "magnitudes %g to %g in bins of dm = %g make %ld bins: at most %ld "
                       "(choose a wider bin)",
                       (double)lo * dm, (double)hi * dm, dm, hi - lo + 1, BK_MFD_MAX_BINS);
    size_t bins = (size_t)(hi - lo) + 1;
    mfd->incremental = calloc(bins, sizeof *mfd->incremental);
    mfd->cumulative = calloc(bins, sizeof *mfd->cumulative);
    if (!mfd->incremental || !mfd->cumulative) {
        bk_mfd_free(mfd);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu magnitude bins", bins);
    }
    mfd->dm = dm;
    mfd->first_bin = lo;
    mfd->n_bins = bins;
    mfd->n_events = n;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        bk_mag_bin(m[i], dm, &k, NULL);
        ++mfd->incremental[k - lo];
    }
    size_t above = 0;
    for (size_t i = bins; i-- > 0;) {
        above += mfd->incremental[i];
        mfd->cumulative[i] = above;
    }
    return BK_OK;
}

/* ------------------------------------------------------- Mc and b-value --- */

int bk_mc_maxc(const bk_mfd *mfd, double correction, double *mc, bk_error *err)
{
    if (!mfd || mfd->n_bins == 0)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "maximum curvature needs a magnitude-frequency distribution of at least "
                       "1 event");
    if (!isfinite(correction))
        return BK_FAIL(err, BK_ERR_INVALID, "Mc correction %g: must be finite", correction);
    size_t best = 0;
    for (size_t i = 1; i < mfd->n_bins; ++i)
        if (mfd->incremental[i] > mfd->incremental[best])
            best = i;
    /* A correction of whole bins keeps Mc a bin centre, which the binned estimator needs. */
    double shift = floor(correction / mfd->dm + 0.5 + BK_MAG_BIN_EPS);
    *mc = ((double)(mfd->first_bin + (long)best) + shift) * mfd->dm;
    return BK_OK;
}

/* The bin of a completeness magnitude, which must be a bin centre. */
static int mc_bin(double mc, double dm, long *k, bk_error *err)
{
    int rc = check_dm(dm, err);
    if (rc != BK_OK)
        return rc;
    if (!isfinite(mc))
        return BK_FAIL(err, BK_ERR_INVALID, "Mc = %g: must be finite", mc);
    if (!bk_stats_centre_bin(mc, dm, k))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "Mc = %g is not a bin centre: it must be a multiple of the bin width "
                       "dm = %g",
                       mc, dm);
    return BK_OK;
}

int bk_b_value(const double *m, size_t n, double mc, double dm, bk_b_estimate *out,
               bk_error *err)
{
    memset(out, 0, sizeof *out);
    long k_mc = 0;
    int rc = mc_bin(mc, dm, &k_mc, err);
    if (rc != BK_OK)
        return rc;
    /* Bin offsets from Mc are small integers: their sums carry no rounding worth the name,
     * and the mean minus (Mc - dm/2) is formed without cancellation. */
    size_t count = 0;
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        if (!isfinite(m[i]))
            return BK_FAIL(err, BK_ERR_INVALID, "magnitude %zu is %g: must be finite", i, m[i]);
        if ((rc = bk_mag_bin(m[i], dm, &k, err)) != BK_OK)
            return rc;
        if (k >= k_mc) {
            ++count;
            sum += (double)(k - k_mc);
        }
    }
    if (count < BK_B_MIN_EVENTS)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%zu magnitude%s at or above Mc = %g (bins of dm = %g): the b-value "
                       "needs at least %d",
                       count, count == 1 ? "" : "s", (double)k_mc * dm, dm, BK_B_MIN_EVENTS);
    double mean_offset = sum / (double)count;
    double squares = 0.0;
    long k_max = k_mc;
    for (size_t i = 0; i < n; ++i) {
        long k = 0;
        bk_mag_bin(m[i], dm, &k, NULL);
        if (k >= k_mc) {
            double d = (double)(k - k_mc) - mean_offset;
            squares += d * d;
            if (k > k_max)
                k_max = k;
        }
    }
    if (k_max == k_mc)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "all %zu magnitudes at or above Mc = %g fall in one bin of dm = %g: no spread "
                       "to estimate a slope from (a narrower --bin, or a catalog with a range of "
                       "magnitudes)",
                       count, (double)k_mc * dm, dm);
    out->mc = (double)k_mc * dm;
    out->dm = dm;
    out->n = count;
    out->mean = out->mc + mean_offset * dm;
    out->b = LOG10_E / ((mean_offset + 0.5) * dm);
    double nd = (double)count;
    out->sigma = LN_10 * out->b * out->b * dm * sqrt(squares / (nd * (nd - 1.0)));
    out->sigma_aki = out->b / sqrt(nd);
    out->a = log10(nd) + out->b * out->mc;
    return BK_OK;
}

int bk_shi_bolt(const double *m, size_t n, double b, double *sigma, bk_error *err)
{
    if (n < 2)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "Shi & Bolt's error needs at least 2 magnitudes, got %zu", n);
    if (!isfinite(b))
        return BK_FAIL(err, BK_ERR_INVALID, "b = %g: must be finite", b);
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(m[i]))
            return BK_FAIL(err, BK_ERR_INVALID, "magnitude %zu is %g: must be finite", i, m[i]);
        sum += m[i];
    }
    double mean = sum / (double)n, squares = 0.0;
    for (size_t i = 0; i < n; ++i)
        squares += (m[i] - mean) * (m[i] - mean);
    double nd = (double)n;
    *sigma = LN_10 * b * b * sqrt(squares / (nd * (nd - 1.0)));
    return BK_OK;
}

/* ----------------------------------------------------------- power law --- */

int bk_power_law_mle(const double *x, size_t n, double x_min, bk_power_law *out,
                     bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(isfinite(x_min) && x_min > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "power-law threshold x_min = %g: must be finite and > 0", x_min);
    size_t count = 0;
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (isnan(x[i]) || x[i] == INFINITY)
            return BK_FAIL(err, BK_ERR_INVALID, "value %zu is %g: must be finite", i, x[i]);
        if (x[i] >= x_min) {
            ++count;
            sum += log(x[i] / x_min);
        }
    }
    if (count < 2)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%zu value%s at or above x_min = %g: the power-law exponent needs at "
                       "least 2",
                       count, count == 1 ? "" : "s", x_min);
    if (!(sum > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "all %zu values at or above x_min = %g equal it: no exponent", count,
                       x_min);
    out->x_min = x_min;
    out->n = count;
    out->alpha = 1.0 + (double)count / sum;
    out->sigma = (out->alpha - 1.0) / sqrt((double)count);
    return BK_OK;
}

/* ---------------------------------------------------------------- sizes --- */

void bk_size_dist_free(bk_size_dist *dist)
{
    if (!dist)
        return;
    free(dist->count);
    free(dist->log2_count);
    memset(dist, 0, sizeof *dist);
}

int bk_size_dist_build(const int32_t *size, size_t n, bk_size_dist *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (n == 0)
        return BK_FAIL(err, BK_ERR_INVALID, "the size distribution needs at least 1 event, got 0");
    int32_t max = 0;
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (size[i] < 1)
            return BK_FAIL(err, BK_ERR_INVALID,
                           "event %zu involved %d blocks: an event involves at least 1", i,
                           (int)size[i]);
        if (size[i] > max)
            max = size[i];
        sum += (double)size[i];
    }
    size_t n_log2 = 0;
    for (uint32_t s = (uint32_t)max; s > 0; s >>= 1)
        ++n_log2;
    out->count = calloc((size_t)max + 1, sizeof *out->count);
    out->log2_count = calloc(n_log2, sizeof *out->log2_count);
    if (!out->count || !out->log2_count) {
        bk_size_dist_free(out);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for event sizes up to %d blocks",
                       (int)max);
    }
    for (size_t i = 0; i < n; ++i) {
        ++out->count[size[i]];
        size_t j = 0;
        for (uint32_t s = (uint32_t)size[i]; s > 1; s >>= 1)
            ++j;
        ++out->log2_count[j];
    }
    out->n_events = n;
    out->max_size = max;
    out->mean = sum / (double)n;
    out->n_log2 = n_log2;
    return BK_OK;
}

/* ----------------------------------------------------------- recurrence --- */

void bk_recurrence_free(bk_recurrence *rec)
{
    if (!rec)
        return;
    free(rec->interval);
    free(rec->t);
    memset(rec, 0, sizeof *rec);
}

int bk_recurrence_intervals(const double *t, const double *m, size_t n, double m_min,
                            bk_recurrence *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (m && isnan(m_min))
        return BK_FAIL(err, BK_ERR_INVALID, "recurrence threshold is NaN: must be a magnitude");
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        if (isnan(t[i]) || (m && isnan(m[i])))
            return BK_FAIL(err, BK_ERR_INVALID, "event %zu: %s is NaN", i,
                           isnan(t[i]) ? "t_start" : "magnitude");
        if (!m || m[i] >= m_min)
            ++count;
    }
    if (count < 3)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "%zu event%s at or above M = %g: the recurrence intervals' mean and "
                       "coefficient of variation need at least 3",
                       count, count == 1 ? "" : "s", m ? m_min : -INFINITY);
    double *sorted = malloc(count * sizeof *sorted);
    out->interval = malloc((count - 1) * sizeof *out->interval);
    out->t = malloc((count - 1) * sizeof *out->t);
    if (!sorted || !out->interval || !out->t) {
        free(sorted);
        bk_recurrence_free(out);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu recurrence intervals", count);
    }
    size_t k = 0;
    for (size_t i = 0; i < n; ++i)
        if (!m || m[i] >= m_min)
            sorted[k++] = t[i];
    /* Catalogs from elsewhere need not be in time order. */
    qsort(sorted, count, sizeof *sorted, compare_doubles);
    double sum = 0.0;
    for (size_t i = 1; i < count; ++i) {
        out->interval[i - 1] = sorted[i] - sorted[i - 1];
        out->t[i - 1] = sorted[i];
        sum += out->interval[i - 1];
    }
    free(sorted);
    size_t ni = count - 1;
    double mean = sum / (double)ni, squares = 0.0;
    for (size_t i = 0; i < ni; ++i)
        squares += (out->interval[i] - mean) * (out->interval[i] - mean);
    if (!(mean > 0.0) || !isfinite(mean)) {
        double mean_copy = mean;
        bk_recurrence_free(out);
        return BK_FAIL(err, BK_ERR_INVALID,
                       "the mean recurrence interval of %zu events is %g s: must be finite and > 0",
                       count, mean_copy);
    }
    out->m_min = m ? m_min : -INFINITY;
    out->n_events = count;
    out->n_intervals = ni;
    out->mean = mean;
    out->sd = sqrt(squares / (double)(ni - 1));
    out->cv = out->sd / mean;
    return BK_OK;
}

/* ---------------------------------------------------- Kolmogorov-Smirnov --- */

double bk_ks_q(double lambda)
{
    if (isnan(lambda))
        return NAN;
    if (lambda <= 0.0)
        return 1.0;
    double sum = 0.0;
    if (lambda < 1.18) {
        /* The alternating series needs many terms near 0; Jacobi's theta transformation
         * gives 1 - Q = sqrt(2 pi)/lambda sum_{j>=1} exp(-(2j-1)^2 pi^2 / (8 lambda^2)),
         * which needs at most 5 terms here. */
        double c = PI * PI / (8.0 * lambda * lambda);
        for (int j = 1; j <= 100; ++j) {
            double odd = 2.0 * j - 1.0;
            double term = exp(-odd * odd * c);
            sum += term;
            if (term <= 1e-17 * sum)
                break;
        }
        return 1.0 - sqrt(2.0 * PI) / lambda * sum;
    }
    double sign = 1.0;
    for (int j = 1; j <= 100; ++j) {
        double term = exp(-2.0 * j * j * lambda * lambda);
        sum += sign * term;
        if (term <= 1e-17 * sum)
            break;
        sign = -sign;
    }
    return 2.0 * sum;
}

/* A sorted copy; NULL (and a message) when out of memory or a value is NaN. */
static double *sorted_sample(const double *x, size_t n, const char *name, bk_error *err)
{
    for (size_t i = 0; i < n; ++i)
        if (isnan(x[i])) {
            BK_FAIL(err, BK_ERR_INVALID, "KS test: value %zu of sample %s is NaN", i, name);
            return NULL;
        }
    double *copy = malloc(n * sizeof *copy);
    if (!copy) {
        BK_FAIL(err, BK_ERR_NOMEM, "KS test: out of memory for %zu values", n);
        return NULL;
    }
    memcpy(copy, x, n * sizeof *copy);
    qsort(copy, n, sizeof *copy, compare_doubles);
    return copy;
}

int bk_ks_two_sample(const double *x1, size_t n1, const double *x2, size_t n2,
                     bk_ks_result *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (n1 == 0 || n2 == 0)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "KS test: samples of %zu and %zu values: each needs at least 1", n1, n2);
    double *a = sorted_sample(x1, n1, "1", err);
    double *b = a ? sorted_sample(x2, n2, "2", err) : NULL;
    if (!a || !b) {
        free(a);
        return err ? err->status : BK_ERR_INVALID;
    }
    /* Both distribution functions step past every copy of a tied value before they are
     * compared: comparing in between would count a difference no sample shows. */
    size_t i = 0, j = 0;
    double d = 0.0;
    while (i < n1 && j < n2) {
        double x = a[i] < b[j] ? a[i] : b[j];
        while (i < n1 && a[i] <= x)
            ++i;
        while (j < n2 && b[j] <= x)
            ++j;
        double diff = fabs((double)i / (double)n1 - (double)j / (double)n2);
        if (diff > d)
            d = diff;
    }
    /* Once one sample is used up its function is 1 and the gap only closes. */
    free(a);
    free(b);
    out->n1 = n1;
    out->n2 = n2;
    out->d = d;
    out->ne = (double)n1 * (double)n2 / ((double)n1 + (double)n2);
    double root = sqrt(out->ne);
    out->lambda = (root + 0.12 + 0.11 / root) * d;
    out->p = bk_ks_q(out->lambda);
    return BK_OK;
}
