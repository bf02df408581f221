/* Mainshocks, their aftershock and foreshock sequences, and the Omori-Utsu law fitted to them
 * (bksim/stats.h, "mainshock sequences").  Stacking follows the superposed-epoch practice of
 * simulator studies: every mainshock's window is shifted to start at its mainshock and the
 * offsets fitted as one sequence, which a single mainshock rarely supports alone. */
#include "bksim/stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct timed {
    double t, m;
} timed;

static int by_time(const void *pa, const void *pb)
{
    const timed *a = pa, *b = pb;
    return (a->t > b->t) - (a->t < b->t);
}

/* First index with time >= t (lower) or > t (upper) in the sorted events. */
static size_t first_at_or_after(const timed *e, size_t n, double t, int strictly)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (strictly ? e[mid].t <= t : e[mid].t < t)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Whether event i is the largest within +-window: no other event there is larger, and none
 * of equal magnitude starts earlier (so of two equal events one is the mainshock). */
static int largest_in_window(const timed *e, size_t n, size_t i, double window)
{
    size_t from = first_at_or_after(e, n, e[i].t - window, 0);
    size_t to = first_at_or_after(e, n, e[i].t + window, 1);
    for (size_t j = from; j < to; ++j)
        if (j != i && (e[j].m > e[i].m || (j < i && e[j].m == e[i].m)))
            return 0;
    return 1;
}

static void fit_stack(bk_sequence_stack *s, double window, const char *what)
{
    bk_error inner = {0};
    if (s->n < BK_OMORI_MIN_EVENTS) {
        snprintf(s->note, sizeof s->note, "%zu %s in all windows: the Omori-Utsu fit needs at least %d", s->n, what,
                 BK_OMORI_MIN_EVENTS);
        return;
    }
    if (bk_omori_fit(s->offset, s->n, 0.0, window, &s->fit, &inner) != BK_OK) {
        snprintf(s->note, sizeof s->note, "%s", inner.message);
        return;
    }
    s->have_fit = 1;
    s->have_residuals = bk_omori_residual_check(s->offset, s->n, &s->fit, &s->residuals, &inner) == BK_OK;
}

static int check_arguments(const double *t, const double *m, size_t n, double m_min, double m_main, double window,
                           double span_start, double span_end, bk_error *err)
{
    if (!(isfinite(window) && window > 0.0))
        return BK_FAIL(err, BK_ERR_INVALID, "sequence window %g s: allowed > 0 and finite", window);
    if (!(isfinite(m_min) && isfinite(m_main)))
        return BK_FAIL(err, BK_ERR_INVALID, "sequence magnitudes m_min = %g, m_main = %g: must be finite", m_min,
                       m_main);
    if (!(isfinite(span_start) && isfinite(span_end) && span_start < span_end))
        return BK_FAIL(err, BK_ERR_INVALID, "observed span [%g, %g] s: allowed start < end, both finite",
                       span_start, span_end);
    for (size_t i = 0; i < n; ++i)
        if (!(isfinite(t[i]) && isfinite(m[i])))
            return BK_FAIL(err, BK_ERR_INVALID, "event %zu: t = %g s, m = %g: both must be finite", i, t[i], m[i]);
    return BK_OK;
}

/* Offsets of the events >= m_min in (t0, t0 + window] (after) or [t0 - window, t0) (before). */
static size_t collect(const timed *e, size_t n, size_t i, double window, double m_min, int after, double *out)
{
    double t0 = e[i].t;
    size_t from = after ? first_at_or_after(e, n, t0, 1) : first_at_or_after(e, n, t0 - window, 0);
    size_t to = after ? first_at_or_after(e, n, t0 + window, 1) : first_at_or_after(e, n, t0, 0);
    size_t count = 0;
    for (size_t j = from; j < to; ++j)
        if (e[j].m >= m_min) {
            if (out)
                out[count] = after ? e[j].t - t0 : t0 - e[j].t;
            ++count;
        }
    return count;
}

int bk_sequences_build(const double *t, const double *m, size_t n, double m_min, double m_main, double window,
                       double span_start, double span_end, bk_sequences *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_arguments(t, m, n, m_min, m_main, window, span_start, span_end, err);
    if (rc != BK_OK)
        return rc;
    out->m_main = m_main;
    out->m_min = m_min;
    out->window = window;
    timed *e = malloc((n ? n : 1) * sizeof *e);
    if (!e)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu events", n);
    for (size_t i = 0; i < n; ++i)
        e[i] = (timed){t[i], m[i]};
    qsort(e, n, sizeof *e, by_time);

    /* Two passes over the mainshocks: count, then fill the stacks. */
    size_t n_after = 0, n_before = 0;
    for (size_t i = 0; i < n; ++i) {
        if (e[i].m < m_main)
            continue;
        ++out->n_candidates;
        if (!largest_in_window(e, n, i, window)) {
            ++out->n_not_largest;
        } else if (e[i].t - window < span_start || e[i].t + window > span_end) {
            ++out->n_at_edges;
        } else {
            ++out->n_mainshocks;
            n_after += collect(e, n, i, window, m_min, 1, NULL);
            n_before += collect(e, n, i, window, m_min, 0, NULL);
        }
    }
    out->sequence = calloc(out->n_mainshocks ? out->n_mainshocks : 1, sizeof *out->sequence);
    out->after.offset = malloc((n_after ? n_after : 1) * sizeof(double));
    out->before.offset = malloc((n_before ? n_before : 1) * sizeof(double));
    if (!out->sequence || !out->after.offset || !out->before.offset) {
        free(e);
        bk_sequences_free(out);
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu sequences", out->n_mainshocks);
    }
    size_t k = 0;
    for (size_t i = 0; i < n && k < out->n_mainshocks; ++i) {
        if (e[i].m < m_main || !largest_in_window(e, n, i, window) || e[i].t - window < span_start ||
            e[i].t + window > span_end)
            continue;
        bk_sequence *s = &out->sequence[k++];
        s->t_main = e[i].t;
        s->m_main = e[i].m;
        double *after = out->after.offset + out->after.n;
        s->n_after = collect(e, n, i, window, m_min, 1, after);
        s->n_before = collect(e, n, i, window, m_min, 0, out->before.offset + out->before.n);
        out->after.n += s->n_after;
        out->before.n += s->n_before;
        /* Events at the mainshock's own instant: neither after nor before it. */
        for (size_t j = first_at_or_after(e, n, e[i].t, 0); j < n && e[j].t == e[i].t; ++j)
            out->n_simultaneous += j != i && e[j].m >= m_min;
        if (s->n_after >= BK_OMORI_MIN_EVENTS) {
            bk_error inner = {0};
            s->have_fit = bk_omori_fit(after, s->n_after, 0.0, window, &s->fit, &inner) == BK_OK;
            out->n_fitted += (size_t)s->have_fit;
        }
    }
    free(e);
    if (out->n_mainshocks == 0) {
        const char *why = "no mainshock";
        snprintf(out->after.note, sizeof out->after.note, "%s", why);
        snprintf(out->before.note, sizeof out->before.note, "%s", why);
        return BK_OK;
    }
    fit_stack(&out->after, window, "aftershocks");
    fit_stack(&out->before, window, "foreshocks");
    return BK_OK;
}

void bk_sequences_free(bk_sequences *s)
{
    free(s->sequence);
    free(s->after.offset);
    free(s->before.offset);
    bk_omori_residuals_free(&s->after.residuals);
    bk_omori_residuals_free(&s->before.residuals);
    memset(s, 0, sizeof *s);
}
