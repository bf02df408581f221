/* The rupture catalog builder (bksim/rupture.h).
 *
 * Open ruptures are the components of a union-find over rupture nodes; each root keeps the
 * list of its episodes and the list of the nodes merged into it, so a merge costs O(1) and a
 * completed rupture frees exactly what it used.  Each block points to its latest episode in
 * an open rupture, which is all a new onset needs to find what it links to: the episodes of
 * the block itself and of its neighbours that still run, or stopped at this very instant.
 * Every figure of a completed rupture is computed from its episodes sorted by (block, onset),
 * so the result does not depend on the order of merges or on a checkpoint in between. */
#include "bksim/rupture.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/modes.h"
#include "capacity.h"
#include "extent.h"

/* Checkpoint values: a format tag, then the counts (see bk_ruptures_save). */
#define SAVE_FORMAT 1.0
#define NONE (-1)

typedef struct episode {
    int32_t block;
    int32_t next;            /* next episode of its rupture (or of the free list); NONE */
    int32_t node;            /* a rupture node it belongs to: find() gives the root */
    int open;
    double t_onset, t_stop;  /* s */
    double x_onset, x_stop;  /* m */
    double f_onset, f_stop;  /* N */
    double peak;             /* m/s, the largest sampled |v| */
    double *samples;         /* (t, |v|) pairs in time order */
    size_t n_samples, capacity;
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
    double *grid;
    size_t grid_capacity;
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
    b->free_episode = b->free_node = NONE;
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
        free(b->episodes[e].samples);
    free(b->latest);
    free(b->episodes);
    free(b->nodes);
    free(b->pending);
    free(b->order);
    free(b->block_list);
    free(b->lines);
    free(b->blocks_out);
    free(b->grid);
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
        b->episodes[e].samples = NULL;
        b->episodes[e].capacity = 0;
    }
    episode *ep = &b->episodes[e];
    double *samples = ep->samples;
    size_t capacity = ep->capacity;
    memset(ep, 0, sizeof *ep);
    ep->samples = samples; /* kept for reuse */
    ep->capacity = capacity;
    ep->next = ep->node = NONE;
    return e;
}

static void release_episode(bk_ruptures *b, int32_t e)
{
    episode *ep = &b->episodes[e];
    if (b->latest[ep->block] == e)
        b->latest[ep->block] = NONE;
    /* A long episode's samples are not kept for the next one. */
    if (ep->capacity > 256) {
        free(ep->samples);
        ep->samples = NULL;
        ep->capacity = 0;
    }
    ep->n_samples = 0;
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
    }
    b->nodes[r] = (node){.parent = NONE, .head = NONE, .tail = NONE, .merged = NONE,
                         .merged_tail = NONE, .next_node = NONE, .live = 1};
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

/* Root `from` joins root `into`: its episodes, its merged nodes and itself. */
static void merge(bk_ruptures *b, int32_t into, int32_t from)
{
    node *a = &b->nodes[into], *c = &b->nodes[from];
    if (c->head != NONE) {
        if (a->tail == NONE)
            a->head = c->head;
        else
            b->episodes[a->tail].next = c->head;
        a->tail = c->tail;
    }
    a->n_open += c->n_open;
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
    c->pending = 0;
}

static int push_sample(episode *ep, double t, double speed)
{
    int dropped = 0;
    while (ep->n_samples > 0 && ep->samples[2 * (ep->n_samples - 1)] > t) {
        ep->n_samples--;
        dropped = 1;
    }
    if (ep->n_samples > 0 && ep->samples[2 * (ep->n_samples - 1)] == t) {
        ep->samples[2 * (ep->n_samples - 1) + 1] = speed;
    } else {
        double *grown = bk_grow_array(ep->samples, &ep->capacity, 2 * (ep->n_samples + 1), sizeof *grown, 8);
        if (!grown)
            return BK_ERR_NOMEM;
        ep->samples = grown;
        ep->samples[2 * ep->n_samples] = t;
        ep->samples[2 * ep->n_samples + 1] = speed;
        ep->n_samples++;
    }
    if (dropped) { /* the peak of what is left */
        ep->peak = 0.0;
        for (size_t k = 0; k < ep->n_samples; ++k)
            ep->peak = fmax(ep->peak, ep->samples[2 * k + 1]);
    } else {
        ep->peak = fmax(ep->peak, speed);
    }
    return BK_OK;
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
            merge(b, root, roots[q]);
    }
    episode *ep = &b->episodes[e];
    ep->block = (int32_t)i;
    ep->open = 1;
    ep->t_onset = t;
    ep->t_stop = NAN;
    ep->x_onset = x;
    ep->f_onset = force;
    append_episode(b, root, e);
    b->nodes[root].n_open++;
    b->nodes[root].pending = 0;
    b->latest[i] = e;
    return push_sample(ep, t, fabs(v));
}

static int stop(bk_ruptures *b, size_t i, double t, double x, double v, double force)
{
    int32_t e = b->latest[i];
    episode *ep = &b->episodes[e];
    int rc = push_sample(ep, t, fabs(v));
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

static int compare_double(const void *a, const void *c)
{
    double x = *(const double *)a, y = *(const double *)c;
    return (x > y) - (x < y);
}

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
        for (int side = 0; side < 2; ++side) {
            if (side == 0 ? dc > 0.0 : dc < 0.0)
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
    size_t k = 0, n_samples = 0;
    for (int32_t e = b->nodes[r].head; e != NONE; e = b->episodes[e].next) {
        order[k++] = e;
        n_samples += b->episodes[e].n_samples;
    }
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
        rup.potency += fabs(ep->x_stop - ep->x_onset);
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
    /* slip: the last stop minus the first onset of each block. */
    for (k = 0, j = 0; k < n_ep; ++k) {
        const episode *ep = &b->episodes[order[k]];
        if (k == 0 || ep->block != b->episodes[order[k - 1]].block)
            blocks[j++].slip = -ep->x_onset;
        if (k + 1 == n_ep || b->episodes[order[k + 1]].block != ep->block)
            blocks[j - 1].slip += ep->x_stop;
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

    /* The rate on the union of the episodes' sample times, each episode linear between its
     * samples and zero outside them; added in the sorted episode order. */
    size_t n_rate = 0;
    if (b->keep_rate && n_samples > 0) {
        double *grid = bk_grow_array(b->grid, &b->grid_capacity, n_samples, sizeof *grid, 64);
        if (!grid)
            return BK_ERR_NOMEM;
        b->grid = grid;
        size_t g = 0;
        for (k = 0; k < n_ep; ++k) {
            const episode *ep = &b->episodes[order[k]];
            for (size_t q = 0; q < ep->n_samples; ++q)
                grid[g++] = ep->samples[2 * q];
        }
        qsort(grid, g, sizeof *grid, compare_double);
        for (size_t q = 0; q < g; ++q)
            if (n_rate == 0 || grid[q] != grid[n_rate - 1])
                grid[n_rate++] = grid[q];
        bk_rupture_rate *rate = bk_grow_array(b->rate_out, &b->rate_out_capacity, n_rate, sizeof *rate, 64);
        if (!rate)
            return BK_ERR_NOMEM;
        b->rate_out = rate;
        for (size_t q = 0; q < n_rate; ++q)
            rate[q] = (bk_rupture_rate){.rupture = b->ruptures, .t = grid[q], .rate = 0.0};
        for (k = 0; k < n_ep; ++k) {
            const episode *ep = &b->episodes[order[k]];
            if (ep->n_samples == 0)
                continue;
            const double *s = ep->samples;
            /* The first grid point at or after the episode's first sample. */
            size_t lo = 0, hi = n_rate;
            while (lo < hi) {
                size_t mid = lo + (hi - lo) / 2;
                if (grid[mid] < s[0])
                    lo = mid + 1;
                else
                    hi = mid;
            }
            size_t q = 0;
            for (size_t p = lo; p < n_rate && grid[p] <= s[2 * (ep->n_samples - 1)]; ++p) {
                while (q + 1 < ep->n_samples && s[2 * (q + 1)] < grid[p])
                    q++;
                double value;
                if (s[2 * q] == grid[p] || q + 1 == ep->n_samples) {
                    value = s[2 * q + 1];
                } else {
                    double w = (grid[p] - s[2 * q]) / (s[2 * (q + 1)] - s[2 * q]);
                    value = s[2 * q + 1] + w * (s[2 * q + 3] - s[2 * q + 1]);
                }
                rate[p].rate += value;
            }
        }
    }
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
        return push_sample(&b->episodes[b->latest[i]], tr->t, fabs(tr->v));
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
    return push_sample(&b->episodes[b->latest[i]], t, speed);
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
            rc = push_sample(ep, t, v ? fabs(v[i]) : 0.0);
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
 * episodes; per episode: block, open, t_onset, t_stop, x_onset, x_stop, f_onset, f_stop,
 * peak, samples, then the samples' (t, |v|) pairs.  Roots in pool order, episodes in list
 * order. */
#define EPISODE_VALUES 10

size_t bk_ruptures_save(const bk_ruptures *b, double *values, size_t capacity)
{
    size_t n = 6;
    size_t roots = 0;
    for (size_t r = 0; r < b->n_nodes_pool; ++r) {
        const node *nd = &b->nodes[r];
        if (!nd->live || nd->parent != NONE || nd->head == NONE)
            continue;
        roots++;
        n += 2;
        for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next)
            n += EPISODE_VALUES + 2 * b->episodes[e].n_samples;
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
        size_t count = 0;
        for (int32_t e = nd->head; e != NONE; e = b->episodes[e].next)
            count++;
        *w++ = nd->pending;
        *w++ = (double)count;
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
            *w++ = (double)ep->n_samples;
            memcpy(w, ep->samples, 2 * ep->n_samples * sizeof *w);
            w += 2 * ep->n_samples;
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
        if (at + 2 > count || !whole(values[at], 0, 1) || !whole(values[at + 1], 1, (double)count))
            return BK_ERR_INVALID;
        int pending = values[at] != 0.0;
        size_t n_ep = (size_t)values[at + 1];
        at += 2;
        int32_t r = new_node(b);
        if (r == NONE)
            return BK_ERR_NOMEM;
        for (size_t q = 0; q < n_ep; ++q) {
            if (at + EPISODE_VALUES > count)
                return BK_ERR_INVALID;
            const double *v = values + at;
            if (!whole(v[0], 0, (double)b->n - 1) || !whole(v[1], 0, 1) || !whole(v[9], 0, (double)count))
                return BK_ERR_INVALID;
            size_t n_samples = (size_t)v[9];
            if (at + EPISODE_VALUES + 2 * n_samples > count)
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
            double *grown = bk_grow_array(ep->samples, &ep->capacity, 2 * n_samples + 2, sizeof *grown, 8);
            if (!grown)
                return BK_ERR_NOMEM;
            ep->samples = grown;
            memcpy(ep->samples, v + EPISODE_VALUES, 2 * n_samples * sizeof *ep->samples);
            ep->n_samples = n_samples;
            ep->peak = v[8];
            at += EPISODE_VALUES + 2 * n_samples;
            append_episode(b, r, e);
            b->nodes[r].n_open += ep->open;
            /* The block's latest: the running one, else the latest to stop. */
            int32_t held = b->latest[ep->block];
            if (held != NONE && b->episodes[held].open && ep->open)
                return BK_ERR_INVALID; /* two running episodes of one block */
            if (held == NONE || ep->open ||
                (!b->episodes[held].open && ep->t_stop >= b->episodes[held].t_stop))
                b->latest[ep->block] = e;
        }
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
