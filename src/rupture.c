/* The rupture catalog builder (bksim/rupture.h).
 *
 * Open ruptures are the components of a union-find over rupture nodes; each root keeps the
 * list of its episodes and the list of the nodes merged into it, so a merge costs O(1) and a
 * completed rupture frees exactly what it used.  Each block points to its latest episode in
 * an open rupture, which is all a new onset needs to find what it links to: the episodes of
 * the block itself and of its neighbours that still run, or stopped at this very instant.
 * Every figure of a completed rupture is computed from its episodes sorted by (block, onset),
 * so the result does not depend on the order of merges or on a checkpoint in between.
 * The rate is rupture_rate.c's, the pools and the union-find rupture_pool.c's, checkpoints
 * rupture_save.c's, the front speeds rupture_front.c's. */
#include "bksim/rupture.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/modes.h"
#include "capacity.h"
#include "extent.h"
#include "rupture_impl.h"

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
        int32_t root = bk_rupture_find(b, b->episodes[e].node);
        int seen = 0;
        for (size_t q = 0; q < n_roots; ++q)
            seen |= roots[q] == root;
        if (!seen)
            roots[n_roots++] = root;
    }
    int32_t e = bk_rupture_new_episode(b);
    if (e == NONE)
        return BK_ERR_NOMEM;
    int32_t root;
    if (n_roots == 0) {
        root = bk_rupture_new_node(b);
        if (root == NONE) {
            bk_rupture_release_episode(b, e);
            return BK_ERR_NOMEM;
        }
    } else {
        root = roots[0];
        for (size_t q = 1; q < n_roots; ++q)
            if (bk_rupture_merge(b, root, roots[q]) != BK_OK) {
                bk_rupture_release_episode(b, e);
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
    bk_rupture_append_episode(b, root, e);
    b->nodes[root].n_open++;
    b->nodes[root].pending = 0;
    b->latest[i] = e;
    return bk_rupture_push_sample(b, e, t, fabs(v));
}

static int stop(bk_ruptures *b, size_t i, double t, double x, double v, double force)
{
    int32_t e = b->latest[i];
    int rc = bk_rupture_push_sample(b, e, t, fabs(v));
    episode *ep = &b->episodes[e];
    ep->open = 0;
    ep->t_stop = t;
    ep->x_stop = x;
    ep->f_stop = force;
    int32_t root = bk_rupture_find(b, ep->node);
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
    int rc = bk_rupture_fold(b, r, INFINITY);
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
        bk_rupture_release_episode(b, e);
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
        bk_rupture_release_trace(b, k);
    }
    bk_rupture_trace_clear(&b->nodes[r].rate);
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
        return bk_rupture_push_sample(b, b->latest[i], tr->t, fabs(tr->v));
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
    return bk_rupture_push_sample(b, b->latest[i], t, speed);
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
            rc = bk_rupture_push_sample(b, e, t, v ? fabs(v[i]) : 0.0);
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

