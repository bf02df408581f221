/* The moment rate of a rupture (rupture_impl.h).  Each episode keeps its block's speed
 * samples as a trace (piecewise linear in time); a rupture's rate is the sum of its traces on
 * the union of their sample times.  So that a long rupture does not hold every block's every
 * sample until it completes, samples the run has settled (bk_ruptures_settle: no restart can
 * drop them any more) are summed into the rupture's own trace, its rate so far, once the
 * samples held pass a bound that doubles with them: memory follows the rate's rows, not
 * blocks times steps.  A sum keeps, at each point, its value and its limits from the left
 * and to the right, as it jumps where one of its traces starts or ends. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capacity.h"
#include "rupture_impl.h"

static int compare_double(const void *a, const void *c)
{
    double x = *(const double *)a, y = *(const double *)c;
    return (x > y) - (x < y);
}

/* Time of point q. */
static inline double point_t(const trace *tr, size_t q)
{
    return tr->samples[(size_t)tr->stride * q];
}

/* The trace's value at t (*value) and its limits from the left and to the right: linear
 * between its points, 0 outside them and outside (valid_after, until]; a trace jumps from 0
 * at its first point, and back to 0 after its last if it ends there (ends: an episode that
 * stopped; a sum always ends at until).  *cursor: a point index at or before t's, advanced as
 * t grows. */
static void trace_at(const trace *tr, double t, size_t *cursor, int ends, double *left, double *value,
                     double *right)
{
    *left = *value = *right = 0.0;
    if (tr->n == 0 || t < tr->valid_after || t > tr->until || t < point_t(tr, 0) || t > point_t(tr, tr->n - 1))
        return;
    size_t q = *cursor;
    while (q + 1 < tr->n && point_t(tr, q + 1) <= t)
        q++;
    *cursor = q;
    const double *p = tr->samples + (size_t)tr->stride * q;
    int sum = tr->stride == 4;
    if (p[0] == t) {
        *value = sum ? p[2] : p[1];
        *left = q == 0 ? 0.0 : p[1];
        /* A sum ends at until: what follows is another trace's. */
        *right = (q + 1 == tr->n && ends) || t >= tr->until ? 0.0 : sum ? p[3] : p[1];
    } else {
        const double *next = p + tr->stride;
        double from = sum ? p[3] : p[1];
        *left = *value = *right = from + (t - p[0]) / (next[0] - p[0]) * (next[1] - from);
    }
    if (t == tr->valid_after) /* it counts only after t, so from the right only */
        *left = *value = 0.0;
}

/* The first point whose time is at or after t (binary search). */
static size_t first_at(const trace *tr, double t)
{
    size_t lo = 0, hi = tr->n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (point_t(tr, mid) < t)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Drop the points before the last one at or before t (kept: the next piece starts from it)
 * and count only after t from now on; *peak takes the largest value dropped (a speed trace).
 * A trace with nothing after t is emptied (only if it cannot grow: done). */
static void trim_trace(trace *tr, double t, int done, double *peak)
{
    size_t keep_from = first_at(tr, t);
    if (!(keep_from < tr->n && point_t(tr, keep_from) == t) && keep_from > 0)
        keep_from--; /* the last point before t starts what is left */
    if (done && (tr->n == 0 || point_t(tr, tr->n - 1) <= t))
        keep_from = tr->n;
    size_t stride = (size_t)tr->stride;
    for (size_t q = 0; q < keep_from; ++q)
        *peak = fmax(*peak, tr->samples[stride * q + (stride == 4 ? 2 : 1)]);
    memmove(tr->samples, tr->samples + stride * keep_from, stride * (tr->n - keep_from) * sizeof *tr->samples);
    tr->n -= keep_from;
    tr->valid_after = fmax(tr->valid_after, t);
}

/* Sum root r's traces up to W (their sample times in (valid_after, W], unioned) into its
 * rate, and trim them there.  When anything still counts at or before the rate's end (a
 * rupture merged in, an episode begun at that very instant) the rate so far is summed again
 * with them, as one more trace; otherwise the new points are appended to it.  Without a rate
 * only the trimming is done. */
int bk_rupture_fold(bk_ruptures *b, int32_t r, double W)
{
    node *nd = &b->nodes[r];
    trace *rate = &nd->rate;
    /* Does anything count at or before the rate's end? */
    int resum = 0;
    size_t count = 0;
    for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next) {
        const trace *tr = &b->episodes[e].speed;
        size_t q = tr->n ? first_at(tr, tr->valid_after) : 0;
        if (q < tr->n && point_t(tr, q) <= tr->valid_after)
            q++;
        if (q < tr->n && point_t(tr, q) <= rate->until)
            resum = 1;
        count += tr->n;
    }
    resum |= nd->absorbed != NONE;
    if (resum && rate->n > 0) {
        /* The rate so far becomes a trace to sum like the others: what lies beyond W stays
         * in it for a later fold. */
        int32_t k = bk_rupture_new_trace(b);
        if (k == NONE)
            return BK_ERR_NOMEM;
        nd = &b->nodes[r];
        rate = &nd->rate;
        trace spare = b->traces[k];
        b->traces[k] = *rate;
        b->traces[k].valid_after = -INFINITY;
        b->traces[k].next = nd->absorbed;
        nd->absorbed = k;
        nd->held += (long)rate->n;
        *rate = (trace){spare.samples, 0, spare.capacity, -INFINITY, -INFINITY, NONE, 4};
    }
    for (int32_t k = nd->absorbed; k != NONE; k = b->traces[k].next)
        count += b->traces[k].n;
    double *grid = bk_grow_array(b->grid, &b->grid_capacity, count ? count : 1, sizeof *grid, 64);
    if (!grid)
        return BK_ERR_NOMEM;
    b->grid = grid;
    size_t g = 0;
#define COLLECT(tr)                                                                     \
    for (size_t q = 0; q < (tr)->n; ++q) {                                              \
        double t = point_t((tr), q);                                                    \
        if (t > (tr)->valid_after && t <= (tr)->until && t <= W)                        \
            grid[g++] = t;                                                              \
    }
    for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next)
        COLLECT(&b->episodes[e].speed)
    for (int32_t k = nd->absorbed; k != NONE; k = b->traces[k].next)
        COLLECT(&b->traces[k])
#undef COLLECT
    qsort(grid, g, sizeof *grid, compare_double);
    size_t n_grid = 0;
    for (size_t q = 0; q < g; ++q)
        if (n_grid == 0 || grid[q] != grid[n_grid - 1])
            grid[n_grid++] = grid[q];
    if (n_grid == 0) { /* nothing settled yet: wait until twice as much is held */
        long episodes = 0;
        for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next)
            episodes++;
        nd->fold_at = 2 * nd->held > 4 * episodes + 256 ? 2 * nd->held : 4 * episodes + 256;
        return BK_OK;
    }
    double last = grid[n_grid - 1];
    if (b->keep_rate) {
        /* Left limit, value and right limit at every grid point, summed trace by trace (each
         * walked once along the grid): the absorbed sums, then the episodes, in list order. */
        double *values = bk_grow_array(b->values, &b->values_capacity, 3 * n_grid, sizeof *values, 64);
        if (!values)
            return BK_ERR_NOMEM;
        b->values = values;
        for (size_t q = 0; q < 3 * n_grid; ++q)
            values[q] = 0.0;
#define ADD(tr, ends)                                                                   \
    do {                                                                                \
        if ((tr)->n == 0)                                                               \
            break;                                                                      \
        size_t cursor = 0, lo = 0, hi = n_grid;                                         \
        while (lo < hi) { /* the first grid point at or after the trace's first */      \
            size_t mid = lo + (hi - lo) / 2;                                            \
            if (grid[mid] < point_t((tr), 0))                                           \
                lo = mid + 1;                                                           \
            else                                                                        \
                hi = mid;                                                               \
        }                                                                               \
        for (size_t p = lo; p < n_grid && grid[p] <= point_t((tr), (tr)->n - 1); ++p) { \
            double l, v, rr;                                                            \
            trace_at((tr), grid[p], &cursor, (ends), &l, &v, &rr);                      \
            values[3 * p] += l;                                                         \
            values[3 * p + 1] += v;                                                     \
            values[3 * p + 2] += rr;                                                    \
        }                                                                               \
    } while (0)
        for (int32_t k = nd->absorbed; k != NONE; k = b->traces[k].next)
            ADD(&b->traces[k], 1);
        for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next)
            ADD(&b->episodes[e].speed, !b->episodes[e].open);
#undef ADD
        size_t base = rate->n;
        double *grown = bk_grow_array(rate->samples, &rate->capacity, 4 * (base + n_grid), sizeof *grown, 64);
        if (!grown)
            return BK_ERR_NOMEM;
        rate->samples = grown;
        for (size_t q = 0; q < n_grid; ++q) {
            double *point = grown + 4 * (base + q);
            point[0] = grid[q];
            point[1] = values[3 * q];
            point[2] = values[3 * q + 1];
            point[3] = values[3 * q + 2];
        }
        rate->n = base + n_grid;
        rate->until = last;
    }
    /* Trim: what was summed is gone from the traces, but the sample each next piece starts
     * from. */
    long held = 0, episodes = 0;
    for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next) {
        episode *ep = &b->episodes[e];
        trim_trace(&ep->speed, last, !ep->open, &ep->peak_folded);
        held += (long)ep->speed.n;
        episodes++;
    }
    int32_t *link = &nd->absorbed;
    while (*link != NONE) {
        int32_t k = *link;
        double ignored = 0.0;
        trim_trace(&b->traces[k], last, 1, &ignored);
        if (b->traces[k].n == 0) {
            *link = b->traces[k].next;
            bk_rupture_release_trace(b, k);
        } else {
            held += (long)b->traces[k].n;
            link = &b->traces[k].next;
        }
    }
    nd = &b->nodes[r];
    nd->held = held;
    nd->fold_at = 2 * held > 4 * episodes + 256 ? 2 * held : 4 * episodes + 256;
    return BK_OK;
}

/* Samples up to where every open episode of root r has settled are final: fold there when
 * the samples held have passed the bound. */
static int maybe_fold(bk_ruptures *b, int32_t r)
{
    if (b->nodes[r].held <= b->nodes[r].fold_at)
        return BK_OK;
    double W = INFINITY;
    for (int32_t e = b->nodes[r].head; e != NONE; e = b->episodes[e].next)
        if (b->episodes[e].open)
            W = fmin(W, b->episodes[e].settled);
    return bk_rupture_fold(b, r, W);
}

/* A speed sample of episode e at t: those after t are dropped (a trajectory the run
 * discarded), one at t replaced. */
int bk_rupture_push_sample(bk_ruptures *b, int32_t e, double t, double speed)
{
    episode *ep = &b->episodes[e];
    trace *tr = &ep->speed;
    if (!(t > tr->valid_after) && tr->valid_after > -INFINITY) {
        return BK_OK; /* already summed: settled samples are never taken back */
    }
    int32_t root = bk_rupture_find(b, ep->node);
    size_t before = tr->n;
    int recompute = 0;
    while (tr->n > 0 && tr->samples[2 * (tr->n - 1)] > t) {
        tr->n--;
        recompute = 1;
    }
    if (tr->n > 0 && tr->samples[2 * (tr->n - 1)] == t) {
        recompute |= tr->samples[2 * (tr->n - 1) + 1] > speed;
        tr->samples[2 * (tr->n - 1) + 1] = speed;
    } else {
        double *grown = bk_grow_array(tr->samples, &tr->capacity, 2 * (tr->n + 1), sizeof *grown, 8);
        if (!grown)
            return BK_ERR_NOMEM;
        tr->samples = grown;
        tr->samples[2 * tr->n] = t;
        tr->samples[2 * tr->n + 1] = speed;
        tr->n++;
    }
    b->nodes[root].held += (long)tr->n - (long)before;
    if (recompute) { /* the peak of what is left */
        ep->peak = ep->peak_folded;
        for (size_t k = 0; k < tr->n; ++k)
            ep->peak = fmax(ep->peak, tr->samples[2 * k + 1]);
    } else {
        ep->peak = fmax(ep->peak, speed);
    }
    return maybe_fold(b, root);
}

