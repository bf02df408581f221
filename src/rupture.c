/* The rupture catalog builder (bksim/rupture.h).
 *
 * Open ruptures are the components of a union-find over rupture nodes; each root keeps the
 * list of its episodes and the list of the nodes merged into it, so a merge costs O(1) and a
 * completed rupture frees exactly what it used.  Each block points to its latest episode in
 * an open rupture, which is all a new onset needs to find what it links to: the episodes of
 * the block itself and of its neighbours that still run, or stopped at this very instant.
 * Every figure of a completed rupture is computed from its episodes sorted by (block, onset),
 * so the result does not depend on the order of merges or on a checkpoint in between.
 *
 * The rate.  Each episode keeps its block's speed samples as a trace (piecewise linear in
 * time); a rupture's rate is the sum of its traces on the union of their sample times.  So
 * that a long rupture does not hold every block's every sample until it completes, samples
 * the run has settled (bk_ruptures_settle: no restart can drop them any more) are folded into
 * the rupture's own summed trace, its rate so far, once the samples held pass a bound that
 * doubles with them: memory follows the rate's rows, not blocks times steps. */
#include "bksim/rupture.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/modes.h"
#include "capacity.h"
#include "extent.h"

/* Checkpoint values: a format tag, then the counts (see bk_ruptures_save). */
#define SAVE_FORMAT 2.0
#define NONE (-1)

/* A piecewise-linear function of time held as (t, value) samples, which counts only at
 * times in (valid_after, until]: what is left of an episode's speeds after a fold, or the
 * summed rate of a rupture absorbed by another. */
typedef struct trace {
    double *samples;         /* per point: (t, value), or for a sum of traces (t, value from the
                                left, value, value to the right): a sum jumps where one of its
                                traces starts or ends */
    size_t n, capacity;      /* points; capacity in doubles */
    double valid_after, until;
    int32_t next;            /* in a rupture's list of absorbed rates, or the free list */
    int stride;              /* doubles per point: 2, or 4 for a sum */
} trace;

typedef struct episode {
    int32_t block;
    int32_t next;            /* next episode of its rupture (or of the free list); NONE */
    int32_t node;            /* a rupture node it belongs to: find() gives the root */
    int open;
    double t_onset, t_stop;  /* s */
    double x_onset, x_stop;  /* m */
    double f_onset, f_stop;  /* N */
    double peak;             /* m/s, the largest sampled |v|, folded samples included */
    double peak_folded;      /* m/s, the largest of the samples folded away */
    double settled;          /* s: samples up to here are final */
    trace speed;             /* its |v| samples (until = +inf) */
} episode;

typedef struct node {
    int32_t parent;          /* NONE: a root */
    int32_t head, tail;      /* a root's episodes */
    int32_t merged;          /* a root's list of nodes merged into it (through next_node) */
    int32_t merged_tail;     /* that list's last node */
    int32_t next_node;       /* in that list, or in the free list */
    int32_t n_open;          /* a root's episodes still running */
    int pending;             /* a root with nothing running since t_now */
    int live;
    trace rate;              /* a root's summed rate up to rate.until (valid_after = -inf) */
    int32_t absorbed;        /* a root's list of traces: rates of ruptures merged into it */
    long held;               /* samples its episodes and absorbed traces hold */
    long fold_at;            /* fold once held passes this */
} node;

struct bk_ruptures {
    size_t n, rows, cols;
    int ring_rows, ring_cols;
    double magnitude_offset;
    int keep_rate;
    bk_rupture_emit_fn emit;
    void *emit_user;
    int32_t *latest;         /* per block: its latest episode in an open rupture, or NONE */
    episode *episodes;
    size_t n_episodes_pool, episodes_capacity;
    int32_t free_episode;
    node *nodes;
    size_t n_nodes_pool, nodes_capacity;
    int32_t free_node;
    trace *traces;           /* absorbed rates */
    size_t n_traces_pool, traces_capacity;
    int32_t free_trace;
    int32_t *pending;        /* roots that went pending at t_now (some may have merged since) */
    size_t n_pending, pending_capacity;
    double t_now;            /* s, the time of the last transition */
    long ruptures, block_rows, rate_rows;
    /* Scratch for completing a rupture. */
    int32_t *order;
    size_t order_capacity;
    int32_t *block_list, *lines;
    size_t block_list_capacity, lines_capacity;
    bk_rupture_block *blocks_out;
    size_t blocks_out_capacity;
    double *grid, *values;
    size_t grid_capacity, values_capacity;
    bk_rupture_rate *rate_out;
    size_t rate_out_capacity;
};

bk_ruptures *bk_ruptures_create(size_t rows, size_t cols, int ring_rows, int ring_cols,
                                double magnitude_offset, int keep_rate, bk_rupture_emit_fn emit,
                                void *emit_user)
{
    if (rows == 0 || cols == 0 || rows * cols > (size_t)INT32_MAX)
        return NULL;
    bk_ruptures *b = calloc(1, sizeof *b);
    if (!b)
        return NULL;
    b->n = rows * cols;
    b->rows = rows;
    b->cols = cols;
    b->ring_rows = ring_rows;
    b->ring_cols = ring_cols;
    b->magnitude_offset = magnitude_offset;
    b->keep_rate = keep_rate;
    b->emit = emit;
    b->emit_user = emit_user;
    b->free_episode = b->free_node = b->free_trace = NONE;
    b->t_now = -INFINITY;
    b->latest = malloc(b->n * sizeof *b->latest);
    if (!b->latest) {
        free(b);
        return NULL;
    }
    for (size_t i = 0; i < b->n; ++i)
        b->latest[i] = NONE;
    return b;
}

void bk_ruptures_free(bk_ruptures *b)
{
    if (!b)
        return;
    for (size_t e = 0; e < b->n_episodes_pool; ++e)
        free(b->episodes[e].speed.samples);
    for (size_t r = 0; r < b->n_nodes_pool; ++r)
        free(b->nodes[r].rate.samples);
    for (size_t k = 0; k < b->n_traces_pool; ++k)
        free(b->traces[k].samples);
    free(b->latest);
    free(b->episodes);
    free(b->nodes);
    free(b->traces);
    free(b->pending);
    free(b->order);
    free(b->block_list);
    free(b->lines);
    free(b->blocks_out);
    free(b->grid);
    free(b->values);
    free(b->rate_out);
    free(b);
}

/* ---------------------------------------------------------------- the pools --- */

static int32_t new_episode(bk_ruptures *b)
{
    int32_t e = b->free_episode;
    if (e != NONE) {
        b->free_episode = b->episodes[e].next;
    } else {
        if (b->n_episodes_pool >= (size_t)INT32_MAX)
            return NONE;
        episode *grown = bk_grow_array(b->episodes, &b->episodes_capacity, b->n_episodes_pool + 1,
                                       sizeof *grown, 64);
        if (!grown)
            return NONE;
        b->episodes = grown;
        e = (int32_t)b->n_episodes_pool++;
        b->episodes[e].speed = (trace){0};
    }
    episode *ep = &b->episodes[e];
    trace kept = ep->speed; /* its buffer, for reuse */
    memset(ep, 0, sizeof *ep);
    ep->speed = (trace){kept.samples, 0, kept.capacity, -INFINITY, INFINITY, NONE, 2};
    ep->next = ep->node = NONE;
    return e;
}

/* Keep a buffer for the next user unless it grew long. */
static void trace_clear(trace *tr)
{
    if (tr->capacity > 256) {
        free(tr->samples);
        tr->samples = NULL;
        tr->capacity = 0;
    }
    tr->n = 0;
}

static int32_t new_trace(bk_ruptures *b)
{
    int32_t k = b->free_trace;
    if (k != NONE) {
        b->free_trace = b->traces[k].next;
    } else {
        if (b->n_traces_pool >= (size_t)INT32_MAX)
            return NONE;
        trace *grown = bk_grow_array(b->traces, &b->traces_capacity, b->n_traces_pool + 1, sizeof *grown, 16);
        if (!grown)
            return NONE;
        b->traces = grown;
        k = (int32_t)b->n_traces_pool++;
        b->traces[k] = (trace){0};
    }
    trace *tr = &b->traces[k];
    *tr = (trace){tr->samples, 0, tr->capacity, -INFINITY, INFINITY, NONE, 4};
    return k;
}

static void release_trace(bk_ruptures *b, int32_t k)
{
    trace_clear(&b->traces[k]);
    b->traces[k].next = b->free_trace;
    b->free_trace = k;
}

static void release_episode(bk_ruptures *b, int32_t e)
{
    episode *ep = &b->episodes[e];
    if (b->latest[ep->block] == e)
        b->latest[ep->block] = NONE;
    trace_clear(&ep->speed);
    ep->next = b->free_episode;
    b->free_episode = e;
}

static int32_t new_node(bk_ruptures *b)
{
    int32_t r = b->free_node;
    if (r != NONE) {
        b->free_node = b->nodes[r].next_node;
    } else {
        if (b->n_nodes_pool >= (size_t)INT32_MAX)
            return NONE;
        node *grown = bk_grow_array(b->nodes, &b->nodes_capacity, b->n_nodes_pool + 1, sizeof *grown, 64);
        if (!grown)
            return NONE;
        b->nodes = grown;
        r = (int32_t)b->n_nodes_pool++;
        b->nodes[r].rate = (trace){0};
    }
    trace rate = b->nodes[r].rate; /* its buffer, for reuse */
    b->nodes[r] = (node){.parent = NONE, .head = NONE, .tail = NONE, .merged = NONE,
                         .merged_tail = NONE, .next_node = NONE, .live = 1, .absorbed = NONE,
                         .fold_at = 256};
    b->nodes[r].rate = (trace){rate.samples, 0, rate.capacity, -INFINITY, -INFINITY, NONE, 4};
    return r;
}

static int32_t find(bk_ruptures *b, int32_t r)
{
    int32_t root = r;
    while (b->nodes[root].parent != NONE)
        root = b->nodes[root].parent;
    while (b->nodes[r].parent != NONE) { /* path compression */
        int32_t up = b->nodes[r].parent;
        b->nodes[r].parent = root;
        r = up;
    }
    return root;
}

static void append_episode(bk_ruptures *b, int32_t root, int32_t e)
{
    node *r = &b->nodes[root];
    b->episodes[e].node = root;
    b->episodes[e].next = NONE;
    if (r->tail == NONE)
        r->head = e;
    else
        b->episodes[r->tail].next = e;
    r->tail = e;
}

/* Root `from` joins root `into`: its episodes, its merged nodes, itself, and its rate so far
 * (an absorbed trace of into's, summed in at the next fold). */
static int merge(bk_ruptures *b, int32_t into, int32_t from)
{
    if (b->nodes[from].rate.n > 0) {
        int32_t k = new_trace(b); /* may move b->traces, never b->nodes */
        if (k == NONE)
            return BK_ERR_NOMEM;
        trace *tr = &b->traces[k];
        trace spare = *tr;
        *tr = b->nodes[from].rate; /* the buffer moves; from keeps the spare */
        tr->valid_after = -INFINITY;
        tr->next = b->nodes[into].absorbed;
        b->nodes[into].absorbed = k;
        b->nodes[into].held += (long)tr->n;
        b->nodes[from].rate = (trace){spare.samples, 0, spare.capacity, -INFINITY, -INFINITY, NONE, 4};
    }
    node *a = &b->nodes[into], *c = &b->nodes[from];
    if (c->head != NONE) {
        if (a->tail == NONE)
            a->head = c->head;
        else
            b->episodes[a->tail].next = c->head;
        a->tail = c->tail;
    }
    a->n_open += c->n_open;
    a->held += c->held;
    /* Its absorbed traces go on into's list. */
    while (c->absorbed != NONE) {
        int32_t k = c->absorbed;
        c->absorbed = b->traces[k].next;
        b->traces[k].next = a->absorbed;
        a->absorbed = k;
    }
    /* from and the nodes merged into it go on into's list: [from, from's list..., into's]. */
    int32_t tail = c->merged_tail != NONE ? c->merged_tail : from;
    c->next_node = c->merged;
    b->nodes[tail].next_node = a->merged;
    if (a->merged == NONE)
        a->merged_tail = tail;
    a->merged = from;
    c->merged = c->merged_tail = NONE;
    c->parent = into;
    c->head = c->tail = NONE;
    c->n_open = 0;
    c->held = 0;
    c->pending = 0;
    return BK_OK;
}

/* ------------------------------------------------------------------ folding --- */

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
static int fold(bk_ruptures *b, int32_t r, double W)
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
        int32_t k = new_trace(b);
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
            release_trace(b, k);
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
    return fold(b, r, W);
}

/* A speed sample of episode e at t: those after t are dropped (a trajectory the run
 * discarded), one at t replaced. */
static int push_sample(bk_ruptures *b, int32_t e, double t, double speed)
{
    episode *ep = &b->episodes[e];
    trace *tr = &ep->speed;
    if (!(t > tr->valid_after) && tr->valid_after > -INFINITY) {
        return BK_OK; /* already summed: settled samples are never taken back */
    }
    int32_t root = find(b, ep->node);
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

/* ------------------------------------------------------------ the neighbours --- */

/* Block i's coupling partners (the model's graph: walls and a one-block periodic direction
 * are none), up to 4; returns how many. */
static size_t neighbours(const bk_ruptures *b, size_t i, size_t out[4])
{
    size_t count = 0, row = i / b->cols, col = i % b->cols;
    if (b->cols > 1) {
        if (col > 0)
            out[count++] = i - 1;
        else if (b->ring_cols)
            out[count++] = i + b->cols - 1;
        if (col + 1 < b->cols)
            out[count++] = i + 1;
        else if (b->ring_cols)
            out[count++] = i + 1 - b->cols;
    }
    if (b->rows > 1) {
        if (row > 0)
            out[count++] = i - b->cols;
        else if (b->ring_rows)
            out[count++] = i + (b->rows - 1) * b->cols;
        if (row + 1 < b->rows)
            out[count++] = i + b->cols;
        else if (b->ring_rows)
            out[count++] = i - (b->rows - 1) * b->cols;
    }
    return count;
}

/* ------------------------------------------------------- onsets and stops --- */

static int onset(bk_ruptures *b, size_t i, double t, double x, double v, double force)
{
    /* The roots this episode links to: block i's own last episode and its neighbours'
     * latest, when they still run or stopped at this instant. */
    size_t partners[5];
    size_t n_partners = neighbours(b, i, partners);
    partners[n_partners++] = i;
    int32_t roots[5] = {NONE, NONE, NONE, NONE, NONE};
    size_t n_roots = 0;
    for (size_t k = 0; k < n_partners; ++k) {
        int32_t e = b->latest[partners[k]];
        if (e == NONE || !(b->episodes[e].open || b->episodes[e].t_stop == t))
            continue;
        int32_t root = find(b, b->episodes[e].node);
        int seen = 0;
        for (size_t q = 0; q < n_roots; ++q)
            seen |= roots[q] == root;
        if (!seen)
            roots[n_roots++] = root;
    }
    int32_t e = new_episode(b);
    if (e == NONE)
        return BK_ERR_NOMEM;
    int32_t root;
    if (n_roots == 0) {
        root = new_node(b);
        if (root == NONE) {
            release_episode(b, e);
            return BK_ERR_NOMEM;
        }
    } else {
        root = roots[0];
        for (size_t q = 1; q < n_roots; ++q)
            if (merge(b, root, roots[q]) != BK_OK) {
                release_episode(b, e);
                return BK_ERR_NOMEM;
            }
    }
    episode *ep = &b->episodes[e];
    ep->block = (int32_t)i;
    ep->open = 1;
    ep->settled = t;
    ep->t_onset = t;
    ep->t_stop = NAN;
    ep->x_onset = x;
    ep->f_onset = force;
    append_episode(b, root, e);
    b->nodes[root].n_open++;
    b->nodes[root].pending = 0;
    b->latest[i] = e;
    return push_sample(b, e, t, fabs(v));
}

static int stop(bk_ruptures *b, size_t i, double t, double x, double v, double force)
{
    int32_t e = b->latest[i];
    int rc = push_sample(b, e, t, fabs(v));
    episode *ep = &b->episodes[e];
    ep->open = 0;
    ep->t_stop = t;
    ep->x_stop = x;
    ep->f_stop = force;
    int32_t root = find(b, ep->node);
    if (--b->nodes[root].n_open > 0)
        return rc;
    b->nodes[root].pending = 1;
    int32_t *grown = bk_grow_array(b->pending, &b->pending_capacity, b->n_pending + 1, sizeof *grown, 16);
    if (!grown)
        return BK_ERR_NOMEM;
    b->pending = grown;
    b->pending[b->n_pending++] = root;
    return rc;
}

/* ----------------------------------------------------- completing a rupture --- */

/* For qsort of episode indices by (block, onset); the builder is passed through a static
 * pointer, as qsort has no user argument (the builder is not reentrant anyway). */
static const episode *sort_episodes;
static int compare_episodes(const void *a, const void *c)
{
    const episode *x = &sort_episodes[*(const int32_t *)a], *y = &sort_episodes[*(const int32_t *)c];
    if (x->block != y->block)
        return (x->block > y->block) - (x->block < y->block);
    return (x->t_onset > y->t_onset) - (x->t_onset < y->t_onset);
}

/* Signed distance from a to b along a direction of len lines (the shorter way on a ring). */
static double line_distance(long a, long c, size_t len, int ring)
{
    long d = c - a;
    if (ring) {
        long n = (long)len;
        d = ((d % n) + n) % n;
        if (d > n / 2)
            d -= n;
    }
    return (double)d;
}

/* The least-squares slope's reciprocal of t against d over n points (see rupture.h). */
static double fit_speed(double sd, double st, double sdd, double sdt, double count)
{
    if (count < 3.0)
        return NAN;
    double var = sdd - sd * sd / count, cov = sdt - sd * st / count;
    if (!(var > 0.0))
        return NAN;
    double slope = cov / var;
    return slope == 0.0 ? INFINITY : slope > 0.0 ? 1.0 / slope : NAN;
}

void bk_rupture_front_speeds(const bk_rupture_block *blocks, size_t n, int32_t epicentre,
                             size_t rows, size_t cols, int ring_rows, int ring_cols, double *left,
                             double *right)
{
    /* Sums of d, t, d^2, d t and counts, per side; times relative to the epicentre's. */
    double s[2][5] = {{0}};
    double t0 = NAN;
    for (size_t k = 0; k < n; ++k)
        if (blocks[k].block == epicentre)
            t0 = blocks[k].t_onset;
    long e_row = epicentre / (long)cols, e_col = epicentre % (long)cols;
    for (size_t k = 0; k < n; ++k) {
        long row = blocks[k].block / (long)cols, col = blocks[k].block % (long)cols;
        double dc = line_distance(e_col, col, cols, ring_cols);
        double dr = rows > 1 ? line_distance(e_row, row, rows, ring_rows) : 0.0;
        double d = rows > 1 ? sqrt(dr * dr + dc * dc) : fabs(dc);
        double t = blocks[k].t_onset - t0;
        /* Sides by column; in the epicentre's column by row, so a one-column lattice reads
         * as a chain. */
        double along = dc != 0.0 ? dc : dr;
        for (int side = 0; side < 2; ++side) {
            if (side == 0 ? along > 0.0 : along < 0.0)
                continue;
            s[side][0] += d;
            s[side][1] += t;
            s[side][2] += d * d;
            s[side][3] += d * t;
            s[side][4] += 1.0;
        }
    }
    *left = fit_speed(s[0][0], s[0][1], s[0][2], s[0][3], s[0][4]);
    *right = fit_speed(s[1][0], s[1][1], s[1][2], s[1][3], s[1][4]);
}

/* The rupture of root r as its row, its blocks and its rate (in the scratch buffers).  open
 * episodes end at t_end with positions x and forces (finish only). */
static int build(bk_ruptures *b, int32_t r, bk_rupture *out, size_t *n_blocks_out, size_t *n_rate_out)
{
    size_t n_ep = 0;
    for (int32_t e = b->nodes[r].head; e != NONE; e = b->episodes[e].next)
        n_ep++;
    int32_t *order = bk_grow_array(b->order, &b->order_capacity, n_ep, sizeof *order, 64);
    if (!order)
        return BK_ERR_NOMEM;
    b->order = order;
    size_t k = 0;
    for (int32_t e = b->nodes[r].head; e != NONE; e = b->episodes[e].next)
        order[k++] = e;
    sort_episodes = b->episodes;
    qsort(order, n_ep, sizeof *order, compare_episodes);

    bk_rupture rup = {.t_start = INFINITY, .t_end = -INFINITY, .first_block = -1, .complete = 1};
    size_t n_blocks = 0;
    for (k = 0; k < n_ep; ++k)
        n_blocks += k == 0 || b->episodes[order[k]].block != b->episodes[order[k - 1]].block;
    bk_rupture_block *blocks = bk_grow_array(b->blocks_out, &b->blocks_out_capacity, n_blocks, sizeof *blocks, 16);
    int32_t *list = bk_grow_array(b->block_list, &b->block_list_capacity, n_blocks, sizeof *list, 16);
    if (blocks)
        b->blocks_out = blocks;
    if (list)
        b->block_list = list;
    if (!blocks || !list)
        return BK_ERR_NOMEM;
    double drop = 0.0;
    size_t j = 0;
    for (k = 0; k < n_ep; ++k) {
        const episode *ep = &b->episodes[order[k]];
        if (ep->t_onset < rup.t_start || (ep->t_onset == rup.t_start && ep->block < rup.first_block)) {
            rup.t_start = ep->t_onset;
            rup.first_block = ep->block;
        }
        rup.t_end = fmax(rup.t_end, ep->t_stop);
        rup.potency += ep->x_stop - ep->x_onset; /* signed: a slip back takes potency away */
        rup.max_slip_rate = fmax(rup.max_slip_rate, ep->peak);
        if (k == 0 || ep->block != b->episodes[order[k - 1]].block) {
            blocks[j] = (bk_rupture_block){.rupture = b->ruptures, .block = ep->block, .t_onset = ep->t_onset};
            list[j] = ep->block;
            drop += ep->f_onset;
            j++;
        }
        blocks[j - 1].t_stop = ep->t_stop; /* the block's last stop, once its last episode is seen */
        if (k + 1 == n_ep || b->episodes[order[k + 1]].block != ep->block)
            drop -= ep->f_stop;
    }
    /* slip: each block's episodes summed (between them another rupture may move it). */
    for (k = 0, j = 0; k < n_ep; ++k) {
        const episode *ep = &b->episodes[order[k]];
        if (k == 0 || ep->block != b->episodes[order[k - 1]].block)
            blocks[j++].slip = 0.0;
        blocks[j - 1].slip += ep->x_stop - ep->x_onset;
    }
    rup.n_blocks = (int32_t)n_blocks;
    rup.n_episodes = (int32_t)n_ep;
    rup.stress_drop = drop / (double)n_blocks;
    rup.duration = rup.t_end - rup.t_start;
    rup.magnitude = rup.potency > 0.0 ? 2.0 / 3.0 * log10(rup.potency) + b->magnitude_offset : -INFINITY;
    if (bk_extent(b->rows, b->cols, b->ring_rows, b->ring_cols, list, n_blocks, &b->lines, &b->lines_capacity,
                  &rup.left, &rup.right) != 0)
        return BK_ERR_NOMEM;
    bk_rupture_front_speeds(blocks, n_blocks, rup.first_block, b->rows, b->cols, b->ring_rows, b->ring_cols,
                            &rup.front_speed_left, &rup.front_speed_right);

    /* The rate: everything folded into the rupture's own trace (every episode has ended). */
    int rc = fold(b, r, INFINITY);
    if (rc != BK_OK)
        return rc;
    const trace *rate = &b->nodes[r].rate;
    size_t n_rate = b->keep_rate ? rate->n : 0;
    bk_rupture_rate *rows = bk_grow_array(b->rate_out, &b->rate_out_capacity, n_rate ? n_rate : 1, sizeof *rows, 64);
    if (!rows)
        return BK_ERR_NOMEM;
    b->rate_out = rows;
    for (size_t q = 0; q < n_rate; ++q)
        rows[q] = (bk_rupture_rate){.rupture = b->ruptures, .t = rate->samples[4 * q], .rate = rate->samples[4 * q + 2]};
    *out = rup;
    *n_blocks_out = n_blocks;
    *n_rate_out = n_rate;
    return BK_OK;
}

/* Free root r, its merged nodes and its episodes. */
static void release_rupture(bk_ruptures *b, int32_t r)
{
    for (int32_t e = b->nodes[r].head; e != NONE;) {
        int32_t next = b->episodes[e].next;
        release_episode(b, e);
        e = next;
    }
    int32_t m = b->nodes[r].merged;
    while (m != NONE) {
        int32_t next = b->nodes[m].next_node;
        b->nodes[m].live = 0;
        b->nodes[m].next_node = b->free_node;
        b->free_node = m;
        m = next;
    }
    while (b->nodes[r].absorbed != NONE) {
        int32_t k = b->nodes[r].absorbed;
        b->nodes[r].absorbed = b->traces[k].next;
        release_trace(b, k);
    }
    trace_clear(&b->nodes[r].rate);
    b->nodes[r].live = 0;
    b->nodes[r].next_node = b->free_node;
    b->free_node = r;
}

static int emit(bk_ruptures *b, int32_t r)
{
    bk_rupture rup;
    size_t n_blocks, n_rate;
    int rc = build(b, r, &rup, &n_blocks, &n_rate);
    if (rc != BK_OK)
        return rc;
    rc = b->emit ? b->emit(b->emit_user, &rup, b->blocks_out, n_blocks, b->rate_out, n_rate) : BK_OK;
    if (rc != BK_OK)
        return rc;
    b->ruptures++;
    b->block_rows += (long)n_blocks;
    b->rate_rows += (long)n_rate;
    release_rupture(b, r);
    return BK_OK;
}

/* (t_start, first_block) of root r, the order ruptures completing together are emitted in. */
typedef struct rupture_key {
    double t_start;
    int32_t first_block;
    int32_t root;
} rupture_key;

static rupture_key key_of(const bk_ruptures *b, int32_t r)
{
    rupture_key key = {INFINITY, INT32_MAX, r};
    for (int32_t e = b->nodes[r].head; e != NONE; e = b->episodes[e].next) {
        const episode *ep = &b->episodes[e];
        if (ep->t_onset < key.t_start || (ep->t_onset == key.t_start && ep->block < key.first_block)) {
            key.t_start = ep->t_onset;
            key.first_block = ep->block;
        }
    }
    return key;
}

static int compare_keys(const void *a, const void *c)
{
    const rupture_key *x = a, *y = c;
    if (x->t_start != y->t_start)
        return (x->t_start > y->t_start) - (x->t_start < y->t_start);
    return (x->first_block > y->first_block) - (x->first_block < y->first_block);
}

/* Emit the roots listed (duplicates and non-roots skipped), in key order. */
static int emit_all(bk_ruptures *b, const int32_t *roots, size_t n)
{
    rupture_key *keys = malloc((n ? n : 1) * sizeof *keys);
    if (!keys)
        return BK_ERR_NOMEM;
    size_t count = 0;
    for (size_t k = 0; k < n; ++k) {
        int32_t r = roots[k];
        node *nd = &b->nodes[r];
        if (!nd->live || nd->parent != NONE || nd->head == NONE)
            continue;
        int dup = 0;
        for (size_t q = 0; q < count && !dup; ++q)
            dup = keys[q].root == r;
        if (!dup)
            keys[count++] = key_of(b, r);
    }
    qsort(keys, count, sizeof *keys, compare_keys);
    int rc = BK_OK;
    for (size_t k = 0; k < count && rc == BK_OK; ++k)
        rc = emit(b, keys[k].root);
    free(keys);
    return rc;
}

static int close_pending(bk_ruptures *b)
{
    /* Roots still pending (an onset at t_now may have taken some on). */
    size_t kept = 0;
    for (size_t k = 0; k < b->n_pending; ++k) {
        int32_t r = b->pending[k];
        if (b->nodes[r].live && b->nodes[r].parent == NONE && b->nodes[r].pending && b->nodes[r].n_open == 0)
            b->pending[kept++] = r;
    }
    b->n_pending = 0;
    return emit_all(b, b->pending, kept);
}

/* --------------------------------------------------------------- the API --- */

int bk_ruptures_begin(bk_ruptures *b, double t, const uint8_t *slipping, const double *x, const double *v,
                      bk_rupture_force_fn force, const void *user)
{
    b->t_now = t;
    for (size_t i = 0; i < b->n; ++i)
        if (slipping[i]) {
            int rc = onset(b, i, t, x[i], v ? v[i] : 0.0, force(user, i));
            if (rc != BK_OK)
                return rc;
        }
    return BK_OK;
}

int bk_ruptures_add(bk_ruptures *b, const bk_transition *tr)
{
    if (tr->block < 0 || (size_t)tr->block >= b->n)
        return BK_ERR_INVALID;
    if (tr->t > b->t_now) {
        if (b->n_pending > 0) {
            int rc = close_pending(b);
            if (rc != BK_OK)
                return rc;
        }
        b->t_now = tr->t;
    }
    size_t i = (size_t)tr->block;
    int slipping = bk_ruptures_slipping(b, i), slips = tr->to != BK_MODE_STICK;
    if (!slipping && slips)
        return onset(b, i, tr->t, tr->x, tr->v, tr->force);
    if (slipping && !slips)
        return stop(b, i, tr->t, tr->x, tr->v, tr->force);
    if (slipping) /* a reversal: the same episode goes on */
        return push_sample(b, b->latest[i], tr->t, fabs(tr->v));
    return BK_OK;
}

int bk_ruptures_slipping(const bk_ruptures *b, size_t i)
{
    int32_t e = b->latest[i];
    return e != NONE && b->episodes[e].open;
}

double bk_ruptures_episode_peak(const bk_ruptures *b, size_t i)
{
    return bk_ruptures_slipping(b, i) ? b->episodes[b->latest[i]].peak : -1.0;
}

int bk_ruptures_sample(bk_ruptures *b, size_t i, double t, double speed)
{
    if (!bk_ruptures_slipping(b, i))
        return BK_OK;
    return push_sample(b, b->latest[i], t, speed);
}

void bk_ruptures_settle(bk_ruptures *b, size_t i, double t)
{
    if (bk_ruptures_slipping(b, i))
        b->episodes[b->latest[i]].settled = fmax(b->episodes[b->latest[i]].settled, t);
}

int bk_ruptures_finish(bk_ruptures *b, double t, const double *x, const double *v, bk_rupture_force_fn force,
                       const void *user)
{
    int rc = b->n_pending > 0 ? close_pending(b) : BK_OK;
    if (rc != BK_OK)
        return rc;
    /* What still runs: its open episodes end at t, the rupture incomplete. */
    size_t n_open = 0;
    for (size_t r = 0; r < b->n_nodes_pool; ++r)
        n_open += b->nodes[r].live && b->nodes[r].parent == NONE && b->nodes[r].head != NONE;
    int32_t *roots = malloc((n_open ? n_open : 1) * sizeof *roots);
    if (!roots)
        return BK_ERR_NOMEM;
    n_open = 0;
    for (size_t r = 0; r < b->n_nodes_pool; ++r)
        if (b->nodes[r].live && b->nodes[r].parent == NONE && b->nodes[r].head != NONE)
            roots[n_open++] = (int32_t)r;
    for (size_t k = 0; k < n_open && rc == BK_OK; ++k)
        for (int32_t e = b->nodes[roots[k]].head; e != NONE && rc == BK_OK; e = b->episodes[e].next) {
            episode *ep = &b->episodes[e];
            if (!ep->open)
                continue;
            size_t i = (size_t)ep->block;
            rc = push_sample(b, e, t, v ? fabs(v[i]) : 0.0);
            ep = &b->episodes[e];
            ep->open = 0;
            ep->t_stop = t;
            ep->x_stop = x[i];
            ep->f_stop = force(user, i);
        }
    /* Incomplete ones are marked by the emitter's view: complete = 0. */
    if (rc == BK_OK) {
        rupture_key *keys = malloc((n_open ? n_open : 1) * sizeof *keys);
        if (!keys) {
            free(roots);
            return BK_ERR_NOMEM;
        }
        for (size_t k = 0; k < n_open; ++k)
            keys[k] = key_of(b, roots[k]);
        qsort(keys, n_open, sizeof *keys, compare_keys);
        for (size_t k = 0; k < n_open && rc == BK_OK; ++k) {
            bk_rupture rup;
            size_t n_blocks, n_rate;
            int32_t r = keys[k].root;
            /* Complete when nothing ran at t (a rupture that stopped at t exactly was pending
             * and went above). */
            rc = build(b, r, &rup, &n_blocks, &n_rate);
            if (rc != BK_OK)
                break;
            rup.complete = b->nodes[r].n_open == 0;
            rc = b->emit ? b->emit(b->emit_user, &rup, b->blocks_out, n_blocks, b->rate_out, n_rate) : BK_OK;
            if (rc != BK_OK)
                break;
            b->ruptures++;
            b->block_rows += (long)n_blocks;
            b->rate_rows += (long)n_rate;
            release_rupture(b, r);
        }
        free(keys);
    }
    free(roots);
    return rc;
}

void bk_ruptures_counts(const bk_ruptures *b, long *ruptures, long *block_rows, long *rate_rows)
{
    if (ruptures)
        *ruptures = b->ruptures;
    if (block_rows)
        *block_rows = b->block_rows;
    if (rate_rows)
        *rate_rows = b->rate_rows;
}

/* ----------------------------------------------------------- checkpoints --- */

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
        int32_t r = new_node(b);
        if (r == NONE)
            return BK_ERR_NOMEM;
        int rc = get_trace(values, count, &at, &b->nodes[r].rate, 4);
        if (rc != BK_OK)
            return rc;
        b->nodes[r].fold_at = fold_at;
        long held = 0;
        int32_t *link = &b->nodes[r].absorbed;
        for (size_t q = 0; q < n_absorbed; ++q) {
            int32_t t = new_trace(b);
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
            int32_t e = new_episode(b);
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
            append_episode(b, r, e);
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
