/* Checkpoints of the rupture builder (bksim/rupture.h: bk_ruptures_save, _restore,
 * _saved_counts): the open ruptures and the counts as doubles. */
#include <math.h>
#include <string.h>

#include "capacity.h"
#include "rupture_impl.h"

/* Checkpoint values: a format tag, then the counts (see bk_ruptures_save). */
#define SAVE_FORMAT 2.0

/* Values: SAVE_FORMAT, ruptures, block_rows, rate_rows, t_now, roots; per root: pending,
 * episodes, fold_at, absorbed traces, its rate trace, the absorbed traces (list order), then
 * per episode (list order): block, open, t_onset, t_stop, x_onset, x_stop, f_onset, f_stop,
 * peak, peak_folded, settled and its speed trace.  A trace: valid_after, until, stride,
 * points, then the points.  Roots in pool order. */
#define EPISODE_VALUES 11
#define TRACE_VALUES 4

static size_t trace_values(const trace *tr)
{
    return TRACE_VALUES + (size_t)tr->stride * tr->n;
}

static double *put_trace(double *w, const trace *tr)
{
    *w++ = tr->valid_after;
    *w++ = tr->until;
    *w++ = tr->stride;
    *w++ = (double)tr->n;
    size_t values = (size_t)tr->stride * tr->n;
    if (values)
        memcpy(w, tr->samples, values * sizeof *w);
    return w + values;
}

size_t bk_ruptures_save(const bk_ruptures *b, double *values, size_t capacity)
{
    size_t n = 6;
    size_t roots = 0;
    for (size_t r = 0; r < b->n_nodes_pool; ++r) {
        const node *nd = &b->nodes[r];
        if (!nd->live || nd->parent != NONE || nd->head == NONE)
            continue;
        roots++;
        n += 4 + trace_values(&nd->rate);
        for (int32_t k = nd->absorbed; k != NONE; k = b->traces[k].next)
            n += trace_values(&b->traces[k]);
        for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next)
            n += EPISODE_VALUES + trace_values(&b->episodes[e].speed);
    }
    if (capacity < n)
        return n;
    double *w = values;
    *w++ = SAVE_FORMAT;
    *w++ = (double)b->ruptures;
    *w++ = (double)b->block_rows;
    *w++ = (double)b->rate_rows;
    *w++ = b->t_now;
    *w++ = (double)roots;
    for (size_t r = 0; r < b->n_nodes_pool; ++r) {
        const node *nd = &b->nodes[r];
        if (!nd->live || nd->parent != NONE || nd->head == NONE)
            continue;
        size_t episodes = 0, absorbed = 0;
        for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next)
            episodes++;
        for (int32_t k = nd->absorbed; k != NONE; k = b->traces[k].next)
            absorbed++;
        *w++ = nd->pending;
        *w++ = (double)episodes;
        *w++ = (double)nd->fold_at;
        *w++ = (double)absorbed;
        w = put_trace(w, &nd->rate);
        for (int32_t k = nd->absorbed; k != NONE; k = b->traces[k].next)
            w = put_trace(w, &b->traces[k]);
        for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next) {
            const episode *ep = &b->episodes[e];
            *w++ = ep->block;
            *w++ = ep->open;
            *w++ = ep->t_onset;
            *w++ = ep->open ? 0.0 : ep->t_stop;
            *w++ = ep->x_onset;
            *w++ = ep->open ? 0.0 : ep->x_stop;
            *w++ = ep->f_onset;
            *w++ = ep->open ? 0.0 : ep->f_stop;
            *w++ = ep->peak;
            *w++ = ep->peak_folded;
            *w++ = ep->settled;
            w = put_trace(w, &ep->speed);
        }
    }
    return n;
}

/* A whole number in [lo, hi]. */
static int whole(double value, double lo, double hi)
{
    return value >= lo && value <= hi && value == floor(value);
}

int bk_ruptures_saved_counts(const double *values, size_t count, long *ruptures, long *block_rows,
                             long *rate_rows)
{
    if (!values || count < 6 || values[0] != SAVE_FORMAT || !whole(values[1], 0, 9e15) ||
        !whole(values[2], 0, 9e15) || !whole(values[3], 0, 9e15))
        return BK_ERR_INVALID;
    *ruptures = (long)values[1];
    *block_rows = (long)values[2];
    *rate_rows = (long)values[3];
    return BK_OK;
}

/* A trace back from values at *at (its buffer reused): a speed trace (stride 2) or a sum
 * (stride 4), as the caller expects; BK_ERR_INVALID when it does not fit. */
static int get_trace(const double *values, size_t count, size_t *at, trace *tr, int stride)
{
    if (*at + TRACE_VALUES > count || values[*at + 2] != stride || !whole(values[*at + 3], 0, (double)count))
        return BK_ERR_INVALID;
    const double *v = values + *at;
    size_t n = (size_t)v[3], size = (size_t)stride * n;
    if (*at + TRACE_VALUES + size > count || isnan(v[0]) || isnan(v[1]))
        return BK_ERR_INVALID;
    const double *points = v + TRACE_VALUES;
    for (size_t q = 0; q < n; ++q) /* times in order */
        if (!isfinite(points[(size_t)stride * q]) ||
            (q > 0 && !(points[(size_t)stride * q] > points[(size_t)stride * (q - 1)])))
            return BK_ERR_INVALID;
    double *grown = bk_grow_array(tr->samples, &tr->capacity, size + 4, sizeof *grown, 8);
    if (!grown)
        return BK_ERR_NOMEM;
    tr->samples = grown;
    if (size)
        memcpy(tr->samples, points, size * sizeof *tr->samples);
    tr->n = n;
    tr->stride = stride;
    tr->valid_after = v[0];
    tr->until = v[1];
    *at += TRACE_VALUES + size;
    return BK_OK;
}

int bk_ruptures_restore(bk_ruptures *b, const double *values, size_t count)
{
    if (b->n_nodes_pool > 0 || b->n_episodes_pool > 0 || count < 6 || values[0] != SAVE_FORMAT ||
        !whole(values[1], 0, 9e15) || !whole(values[2], 0, 9e15) || !whole(values[3], 0, 9e15) ||
        !whole(values[5], 0, (double)count))
        return BK_ERR_INVALID;
    b->ruptures = (long)values[1];
    b->block_rows = (long)values[2];
    b->rate_rows = (long)values[3];
    b->t_now = values[4];
    size_t roots = (size_t)values[5], at = 6;
    for (size_t k = 0; k < roots; ++k) {
        if (at + 4 > count || !whole(values[at], 0, 1) || !whole(values[at + 1], 1, (double)count) ||
            !whole(values[at + 2], 0, 9e15) || !whole(values[at + 3], 0, (double)count))
            return BK_ERR_INVALID;
        int pending = values[at] != 0.0;
        size_t n_ep = (size_t)values[at + 1], n_absorbed = (size_t)values[at + 3];
        long fold_at = (long)values[at + 2];
        at += 4;
        int32_t r = bk_rupture_new_node(b);
        if (r == NONE)
            return BK_ERR_NOMEM;
        int rc = get_trace(values, count, &at, &b->nodes[r].rate, 4);
        if (rc != BK_OK)
            return rc;
        b->nodes[r].fold_at = fold_at;
        long held = 0;
        int32_t *link = &b->nodes[r].absorbed;
        for (size_t q = 0; q < n_absorbed; ++q) {
            int32_t t = bk_rupture_new_trace(b);
            if (t == NONE)
                return BK_ERR_NOMEM;
            *link = t; /* in list order */
            link = &b->traces[t].next;
            if ((rc = get_trace(values, count, &at, &b->traces[t], 4)) != BK_OK)
                return rc;
            held += (long)b->traces[t].n;
        }
        for (size_t q = 0; q < n_ep; ++q) {
            if (at + EPISODE_VALUES > count)
                return BK_ERR_INVALID;
            const double *v = values + at;
            if (!whole(v[0], 0, (double)b->n - 1) || !whole(v[1], 0, 1))
                return BK_ERR_INVALID;
            int32_t e = bk_rupture_new_episode(b);
            if (e == NONE)
                return BK_ERR_NOMEM;
            episode *ep = &b->episodes[e];
            ep->block = (int32_t)v[0];
            ep->open = v[1] != 0.0;
            ep->t_onset = v[2];
            ep->t_stop = ep->open ? NAN : v[3];
            ep->x_onset = v[4];
            ep->x_stop = v[5];
            ep->f_onset = v[6];
            ep->f_stop = v[7];
            ep->peak = v[8];
            ep->peak_folded = v[9];
            ep->settled = v[10];
            at += EPISODE_VALUES;
            bk_rupture_append_episode(b, r, e);
            if ((rc = get_trace(values, count, &at, &b->episodes[e].speed, 2)) != BK_OK)
                return rc;
            ep = &b->episodes[e];
            held += (long)ep->speed.n;
            b->nodes[r].n_open += ep->open;
            /* The block's latest: the running one, else the latest to stop. */
            int32_t had = b->latest[ep->block];
            if (had != NONE && b->episodes[had].open && ep->open)
                return BK_ERR_INVALID; /* two running episodes of one block */
            if (had == NONE || ep->open || (!b->episodes[had].open && ep->t_stop >= b->episodes[had].t_stop))
                b->latest[ep->block] = e;
        }
        b->nodes[r].held = held;
        if (pending != (b->nodes[r].n_open == 0))
            return BK_ERR_INVALID;
        b->nodes[r].pending = pending;
        if (pending) {
            int32_t *grown = bk_grow_array(b->pending, &b->pending_capacity, b->n_pending + 1, sizeof *grown, 16);
            if (!grown)
                return BK_ERR_NOMEM;
            b->pending = grown;
            b->pending[b->n_pending++] = r;
        }
    }
    return at == count ? BK_OK : BK_ERR_INVALID;
}
