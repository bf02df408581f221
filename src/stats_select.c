/* Which rows of a catalog the statistics use, and the span they were observed over: the one
 * rule `bksim stats` and `bksim compare` share (bksim/stats.h, bk_event_select). */
#include "bksim/stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int in_window(double t, double t_from, double t_to)
{
    return !(t < t_from) && !(t >= t_to);
}

/* The run's span (t = 0 to t_reached) when the catalog is a bksim output that reached past
 * every kept start; else the catalog's own, to the latest end of a row starting in the window;
 * either clipped to the window. */
static void set_span(const bk_event_table *t, double t_from, double t_to, bk_event_selection *s)
{
    double start, end;
    if (isfinite(t->t_reached) && t->t_reached > 0.0 && t->t_reached >= s->t_last) {
        start = 0.0;
        end = t->t_reached;
        s->duration_from_run = 1;
    } else {
        start = s->t_first;
        end = s->t_last;
        if (t->t_end)
            for (size_t i = 0; i < t->n; ++i)
                if (isfinite(t->t_end[i]) && t->t_end[i] > end && isfinite(t->t_start[i]) &&
                    in_window(t->t_start[i], t_from, t_to))
                    end = t->t_end[i];
    }
    start = fmax(start, t_from);
    end = fmin(end, t_to);
    s->span_start = start;
    s->duration = s->n_events && end > start ? end - start : 0.0;
}

int bk_event_select(const bk_event_table *t, double t_from, double t_to, bk_event_selection *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    out->index = malloc((t->n ? t->n : 1) * sizeof *out->index);
    if (!out->index)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu events", t->n);
    for (size_t i = 0; i < t->n; ++i) {
        if (t->complete && t->complete[i] == 0) {
            ++out->n_incomplete;
            continue;
        }
        if (!isfinite(t->t_start[i]) || !isfinite(t->magnitude[i])) {
            ++out->n_nonfinite;
            continue;
        }
        if (!in_window(t->t_start[i], t_from, t_to)) {
            ++out->n_outside;
            continue;
        }
        size_t k = out->n_events++;
        out->index[k] = i;
        double ts = t->t_start[i], m = t->magnitude[i];
        out->t_first = k == 0 ? ts : fmin(out->t_first, ts);
        out->t_last = k == 0 ? ts : fmax(out->t_last, ts);
        out->m_min = k == 0 ? m : fmin(out->m_min, m);
        out->m_max = k == 0 ? m : fmax(out->m_max, m);
    }
    set_span(t, t_from, t_to, out);
    return BK_OK;
}

void bk_event_selection_free(bk_event_selection *s)
{
    free(s->index);
    memset(s, 0, sizeof *s);
}
