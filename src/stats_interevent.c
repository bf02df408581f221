/* Interevent times (Corral, PRL 92, 108501, 2004): the times between successive events at or
 * above a magnitude threshold, rescaled by the rate R of such events, theta = tau R, whose
 * density collapses onto one curve for every threshold when the process is scale-free in
 * magnitude (a gamma density with shape about 0.7 for real seismicity; 1, the exponential,
 * for a Poisson process).  The density on logarithmic bins, the coefficient of variation,
 * and the gamma fit by maximum likelihood: shape k from ln k - psi(k) = ln mean - mean ln
 * (Choi & Wette 1969; Newton from Minka's starting value), scale = mean / k, the shape's
 * asymptotic standard error 1 / sqrt(n (psi'(k) - 1/k)). */
#include "bksim/stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_sf_psi.h>

void bk_interevent_free(bk_interevent *ie)
{
    if (!ie)
        return;
    free(ie->theta);
    free(ie->density);
    memset(ie, 0, sizeof *ie);
}

/* The gamma shape whose ln k - psi(k) is s > 0 (that function falls from +inf to 0). */
static double gamma_shape(double s)
{
    double k = (3.0 - s + sqrt((s - 3.0) * (s - 3.0) + 24.0 * s)) / (12.0 * s);
    for (int it = 0; it < 50; ++it) {
        double f = log(k) - gsl_sf_psi(k) - s, df = 1.0 / k - gsl_sf_psi_1(k);
        double next = k - f / df;
        if (!(next > 0.0))
            next = 0.5 * k;
        if (fabs(next - k) <= 1e-14 * k)
            return next;
        k = next;
    }
    return k;
}

int bk_interevent_build(const double *t, const double *m, size_t n, double m_min, double duration,
                        size_t bins_per_decade, bk_interevent *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(isfinite(duration) && duration > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "interevent times: the observed span is %g s: must be > 0", duration);
    if (bins_per_decade < 1 || bins_per_decade > 100)
        return BK_FAIL(err, BK_ERR_INVALID, "interevent times: %zu bins per decade: allowed 1 .. 100",
                       bins_per_decade);
    bk_recurrence rec;
    int rc = bk_recurrence_intervals(t, m, n, m_min, &rec, err);
    if (rc != BK_OK)
        return rc;
    out->m_min = rec.m_min;
    out->n_events = rec.n_events;
    out->n_intervals = rec.n_intervals;
    out->rate = (double)rec.n_events / duration;
    out->cv = rec.cv;
    /* Rescaled; zero intervals (events that start together) have no logarithm: counted. */
    double sum = 0.0, sum_log = 0.0, lo = INFINITY, hi = 0.0;
    size_t positive = 0;
    for (size_t i = 0; i < rec.n_intervals; ++i) {
        double theta = rec.interval[i] * out->rate;
        if (!(theta > 0.0)) {
            out->n_zero++;
            continue;
        }
        ++positive;
        sum += theta;
        sum_log += log(theta);
        lo = fmin(lo, theta);
        hi = fmax(hi, theta);
    }
    if (positive < 2 || hi <= lo) {
        bk_recurrence_free(&rec);
        return BK_FAIL(err, BK_ERR_INVALID,
                       "interevent times at M >= %g: %zu positive intervals%s: the gamma fit needs at least 2 "
                       "that differ",
                       m_min, positive, positive >= 2 ? ", all equal" : "");
    }
    double mean = sum / (double)positive, s = log(mean) - sum_log / (double)positive;
    double k = gamma_shape(s);
    out->gamma_shape = k;
    out->gamma_scale = mean / k;
    out->gamma_shape_sigma = 1.0 / sqrt((double)positive * (gsl_sf_psi_1(k) - 1.0 / k));
    /* Logarithmic bins from the decade below the shortest to above the longest interval. */
    double first = floor(log10(lo) * (double)bins_per_decade), last = ceil(log10(hi) * (double)bins_per_decade);
    if (last <= first)
        last = first + 1.0;
    size_t bins = (size_t)(last - first) + 1;
    out->theta = malloc(bins * sizeof *out->theta);
    out->density = calloc(bins, sizeof *out->density);
    if (!out->theta || !out->density) {
        bk_recurrence_free(&rec);
        bk_interevent_free(out);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu interevent bins", bins);
    }
    double step = 1.0 / (double)bins_per_decade;
    for (size_t i = 0; i < rec.n_intervals; ++i) {
        double theta = rec.interval[i] * out->rate;
        if (!(theta > 0.0))
            continue;
        long b = (long)floor(log10(theta) / step - first);
        if (b < 0)
            b = 0;
        if ((size_t)b >= bins)
            b = (long)bins - 1;
        out->density[b] += 1.0;
    }
    for (size_t b = 0; b < bins; ++b) {
        double edge_lo = pow(10.0, (first + (double)b) * step), edge_hi = pow(10.0, (first + (double)b + 1.0) * step);
        out->theta[b] = sqrt(edge_lo * edge_hi);
        out->density[b] /= (double)positive * (edge_hi - edge_lo);
    }
    out->n_bins = bins;
    bk_recurrence_free(&rec);
    return BK_OK;
}
