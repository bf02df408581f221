/* b-positive (van der Elst, JGR 126, e2020JB021027, 2021): the b-value of the positive
 * magnitude differences between successive events, which a short-term incompleteness after
 * large events (that hides small events, not large ones) does not bias; and the a-value of
 * the same differences, as SeismoStats computes it.  Also the binned maximum-likelihood
 * estimator the two use (Tinti & Mulargia 1987), which SeismoStats calls classic.  The
 * definitions follow SeismoStats (swiss-seismological-service/SeismoStats 4605c4e,
 * seismostats/analysis/bvalue/positive.py, avalue/positive.py, bvalue/classic.py), so that
 * their published values are reproduced (tests/test_stats_positive.c). */
#include "bksim/stats.h"
#include "stats_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LN_10 2.30258509299404568402


int bk_b_tinti(const double *m, size_t n, double mc, double dm, bk_b_estimate *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(isfinite(dm) && dm >= 0.0) || !isfinite(mc))
        return BK_FAIL(err, BK_ERR_INVALID, "binned b-value: Mc = %g, dm = %g: both finite, dm >= 0", mc, dm);
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i)
        if (m[i] >= mc - 0.5 * dm) {
            sum += m[i] - mc;
            ++count;
        }
    if (count == 0)
        return BK_FAIL(err, BK_ERR_INVALID, "binned b-value: no magnitude at or above Mc = %g", mc);
    double mbar = sum / (double)count;
    if (!(mbar > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID,
                       "binned b-value: the %zu magnitudes at or above Mc = %g exceed it by %g on average: the "
                       "estimate needs a positive excess",
                       count, mc, mbar);
    double beta = dm > 0.0 ? log1p(dm / mbar) / dm : 1.0 / mbar;
    double squares = 0.0, mean = mc + mbar;
    for (size_t i = 0; i < n; ++i)
        if (m[i] >= mc - 0.5 * dm)
            squares += (m[i] - mean) * (m[i] - mean);
    out->mc = mc;
    out->dm = dm;
    out->n = count;
    out->mean = mean;
    out->b = beta / LN_10;
    /* Shi & Bolt with the population sd over sqrt(n - 1), as SeismoStats' shi_bolt_confidence. */
    out->sigma = count > 1 ? LN_10 * out->b * out->b * sqrt(squares / (double)count) / sqrt((double)count - 1.0)
                           : NAN; /* one magnitude: no spread */
    out->sigma_aki = out->b / sqrt((double)count);
    out->a = log10((double)count) + out->b * mc;
    return BK_OK;
}

typedef struct timed {
    double t, m;
    size_t index;
} timed;

static int by_time(const void *pa, const void *pb)
{
    const timed *a = pa, *b = pb;
    if (a->t != b->t)
        return (a->t > b->t) - (a->t < b->t);
    return (a->index > b->index) - (a->index < b->index); /* ties in catalog order */
}

int bk_b_positive(const double *m, const double *t, size_t n, double mc, double dm, double dmc,
                  bk_b_positive_estimate *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(isfinite(dm) && dm > 0.0) || !isfinite(mc) || !(isfinite(dmc) && dmc >= 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "b-positive: Mc = %g, dm = %g, dMc = %g: finite, dm > 0, dMc >= 0", mc,
                       dm, dmc);
    timed *ev = malloc((n ? n : 1) * sizeof *ev);
    double *diff = malloc((n ? n : 1) * sizeof *diff);
    if (!ev || !diff) {
        free(ev);
        free(diff);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu magnitudes", n);
    }
    size_t kept = 0;
    for (size_t i = 0; i < n; ++i)
        if (m[i] >= mc - 0.5 * dm)
            ev[kept++] = (timed){t ? t[i] : (double)i, m[i], i};
    qsort(ev, kept, sizeof *ev, by_time);
    size_t count = 0;
    double dt_sum = 0.0;
    for (size_t i = 0; i + 1 < kept; ++i) {
        double d = ev[i + 1].m - ev[i].m;
        if (d >= dmc - 0.5 * dm) {
            diff[count++] = bk_stats_to_bin(d, dm);
            dt_sum += ev[i + 1].t - ev[i].t;
        }
    }
    double span = kept ? ev[kept - 1].t - ev[0].t : 0.0;
    free(ev);
    bk_error inner = {0};
    int rc = bk_b_tinti(diff, count, dmc, dm, &out->fit, &inner);
    free(diff);
    if (rc != BK_OK)
        return BK_FAIL(err, BK_ERR_INVALID,
                       "b-positive: %zu positive differences of at least dMc = %g between the %zu events at or above "
                       "Mc = %g: %s",
                       count, dmc, kept, mc, inner.message);
    out->mc = mc;
    out->dmc = dmc;
    out->n_events = kept;
    /* SeismoStats' a of the positive differences: their count over the fraction of the span
     * the kept pairs cover (not van der Elst & Page's 2023 a-positive, as its docstring says). */
    out->a = t && dt_sum > 0.0 && span > 0.0 ? log10((double)count / (dt_sum / span)) : NAN;
    return BK_OK;
}
