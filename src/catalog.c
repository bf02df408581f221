/* The event catalog builder (bksim/catalog.h).  Per block it keeps what its current event
 * needs (where its slip began, its forces, whether the event has seen it); per event, the
 * list of blocks involved, so that closing an event costs what the event touched. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/catalog.h"
#include "bksim/modes.h"
#include "capacity.h"
#include "extent.h"

struct bk_catalog {
    size_t n;
    size_t rows, cols;    /* the lattice (a chain: 1 x n) */
    int ring_rows, ring_cols;
    double magnitude_offset;
    /* Per block. */
    double *x_onset;      /* m, position where its current slip episode began */
    double *first_force;  /* N, applied force at its first onset in the current event */
    double *last_force;   /* N, applied force at its last stick in the current event */
    long *seen;           /* the last event (serial) it slipped in; -1: none */
    int8_t *slipping;
    size_t n_slipping;
    /* The current event. */
    long serial;
    int open;
    int pending;          /* nothing slips since t_pending: the event ends unless an onset
                             at that same instant carries it on */
    double t_pending;
    bk_event event;
    int32_t *involved;    /* its blocks, in the order they first slipped */
    size_t n_involved, involved_capacity;
    int32_t *lines;       /* a lattice event's columns, scratch */
    size_t lines_capacity;
};

bk_catalog *bk_catalog_create(size_t n_blocks, int ring, double magnitude_offset)
{
    return bk_catalog_create_lattice(1, n_blocks, 0, ring, magnitude_offset);
}

bk_catalog *bk_catalog_create_lattice(size_t rows, size_t cols, int ring_rows, int ring_cols,
                                      double magnitude_offset)
{
    bk_catalog *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    size_t n_blocks = rows * cols;
    c->n = n_blocks;
    c->rows = rows;
    c->cols = cols;
    c->ring_rows = ring_rows;
    c->ring_cols = ring_cols;
    c->magnitude_offset = magnitude_offset;
    /* Zeroed: a checkpoint saves last_force for every block of the open event, and a block
     * that has not stuck yet in it has none, so its saved bytes were undefined (valgrind, on
     * the checkpoint every run now writes at its end). */
    c->x_onset = calloc(n_blocks, sizeof *c->x_onset);
    c->first_force = calloc(n_blocks, sizeof *c->first_force);
    c->last_force = calloc(n_blocks, sizeof *c->last_force);
    c->seen = malloc(n_blocks * sizeof *c->seen);
    c->slipping = calloc(n_blocks, sizeof *c->slipping);
    if (!c->x_onset || !c->first_force || !c->last_force || !c->seen || !c->slipping) {
        bk_catalog_free(c);
        return NULL;
    }
    for (size_t i = 0; i < n_blocks; ++i)
        c->seen[i] = -1;
    c->serial = -1;
    return c;
}

void bk_catalog_free(bk_catalog *c)
{
    if (!c)
        return;
    free(c->x_onset);
    free(c->first_force);
    free(c->last_force);
    free(c->seen);
    free(c->slipping);
    free(c->involved);
    free(c->lines);
    free(c);
}

static int onset(bk_catalog *c, size_t i, double t, double x, double v, double force)
{
    if (!c->open) {
        c->open = 1;
        c->serial++;
        c->n_involved = 0;
        c->event = (bk_event){.t_start = t, .first_block = (int32_t)i, .complete = 1};
    } else if (t == c->event.t_start && (int32_t)i < c->event.first_block) {
        c->event.first_block = (int32_t)i; /* simultaneous first onsets: the lowest index */
    }
    c->pending = 0;
    if (fabs(v) > c->event.max_slip_rate)
        c->event.max_slip_rate = fabs(v);
    c->x_onset[i] = x;
    c->slipping[i] = 1;
    c->n_slipping++;
    if (c->seen[i] != c->serial) {
        int32_t *involved = bk_grow_array(c->involved, &c->involved_capacity, c->n_involved + 1,
                                          sizeof *involved, 64);
        if (!involved)
            return BK_ERR_NOMEM;
        c->involved = involved;
        c->involved[c->n_involved++] = (int32_t)i;
        c->seen[i] = c->serial;
        c->first_force[i] = force;
    }
    return BK_OK;
}

static void episode_end(bk_catalog *c, size_t i, double x, double force)
{
    c->event.potency += fabs(x - c->x_onset[i]);
    c->event.n_episodes++;
    c->last_force[i] = force;
}

static int close_event(bk_catalog *c, double t_end, bk_event *out)
{
    bk_event *e = &c->event;
    e->t_end = t_end;
    e->n_blocks = (int32_t)c->n_involved;
    /* Sorts the blocks: the sum below goes in block order, as after a restore. */
    if (bk_extent(c->rows, c->cols, c->ring_rows, c->ring_cols, c->involved, c->n_involved, &c->lines,
                  &c->lines_capacity, &e->left, &e->right) != 0)
        return BK_ERR_NOMEM;
    double drop = 0.0;
    for (size_t j = 0; j < c->n_involved; ++j)
        drop += c->first_force[c->involved[j]] - c->last_force[c->involved[j]];
    e->stress_drop = drop / (double)c->n_involved;
    e->magnitude = e->potency > 0.0 ? 2.0 / 3.0 * log10(e->potency) + c->magnitude_offset : -INFINITY;
    *out = *e;
    c->open = 0;
    c->pending = 0;
    return BK_OK;
}

int bk_catalog_begin(bk_catalog *c, double t, const int8_t *mode, const double *x, const double *v,
                     bk_catalog_force_fn force, const void *user)
{
    for (size_t i = 0; i < c->n; ++i)
        if (mode[i] != BK_MODE_STICK) {
            int rc = onset(c, i, t, x[i], v ? v[i] : 0.0, force(user, i));
            if (rc != BK_OK)
                return rc;
        }
    return BK_OK;
}

int bk_catalog_add(bk_catalog *c, const bk_transition *tr, bk_event *event, int *done)
{
    *done = 0;
    if (tr->block < 0 || (size_t)tr->block >= c->n)
        return BK_ERR_INVALID;
    if (c->pending && tr->t > c->t_pending) {
        int rc = close_event(c, c->t_pending, event);
        if (rc != BK_OK)
            return rc;
        *done = 1;
    }
    size_t i = (size_t)tr->block;
    int slips = tr->to != BK_MODE_STICK;
    if (!c->slipping[i] && slips)
        return onset(c, i, tr->t, tr->x, tr->v, tr->force);
    if (c->slipping[i] && !slips) {
        episode_end(c, i, tr->x, tr->force);
        c->slipping[i] = 0;
        if (--c->n_slipping == 0) {
            c->pending = 1;
            c->t_pending = tr->t;
        }
    }
    return BK_OK; /* a reversal (slip + to slip -) goes on with the same episode */
}

int bk_catalog_finish(bk_catalog *c, double t, const double *x, bk_catalog_force_fn force,
                      const void *user, bk_event *event)
{
    if (c->pending)
        return close_event(c, c->t_pending, event) == BK_OK ? 1 : BK_ERR_NOMEM;
    if (!c->open)
        return 0;
    /* Still running: its open episodes counted to t, its blocks' forces there. */
    for (size_t j = 0; j < c->n_involved; ++j) {
        size_t i = (size_t)c->involved[j];
        if (c->slipping[i]) {
            episode_end(c, i, x[i], force(user, i));
            c->slipping[i] = 0;
        }
    }
    c->n_slipping = 0;
    if (close_event(c, t, event) != BK_OK)
        return BK_ERR_NOMEM;
    event->complete = 0;
    return 1;
}

void bk_catalog_slip_rate(bk_catalog *c, double slip_rate)
{
    if (c->open && !c->pending && fabs(slip_rate) > c->event.max_slip_rate)
        c->event.max_slip_rate = fabs(slip_rate);
}

double bk_catalog_max_slip_rate(const bk_catalog *c)
{
    return c->open && !c->pending ? c->event.max_slip_rate : -1.0;
}

void bk_catalog_save(const bk_catalog *c, bk_catalog_state *s)
{
    for (size_t i = 0; i < c->n; ++i) {
        int in_event = c->open && c->seen[i] == c->serial;
        s->involved[i] = (uint8_t)in_event;
        s->slipping[i] = (uint8_t)c->slipping[i];
        /* Only what the open event uses: the rest is stale and would make the saved state
         * depend on history a resumed run never sees. */
        s->x_onset[i] = c->slipping[i] ? c->x_onset[i] : 0.0;
        s->first_force[i] = in_event ? c->first_force[i] : 0.0;
        s->last_force[i] = in_event ? c->last_force[i] : 0.0;
    }
    s->open = c->open;
    s->pending = c->pending;
    s->t_pending = c->pending ? c->t_pending : 0.0;
    s->t_start = c->open ? c->event.t_start : 0.0;
    s->first_block = c->open ? c->event.first_block : -1;
    s->n_episodes = c->open ? c->event.n_episodes : 0;
    s->potency = c->open ? c->event.potency : 0.0;
    s->max_slip_rate = c->open ? c->event.max_slip_rate : 0.0;
}

int bk_catalog_restore(bk_catalog *c, const bk_catalog_state *s)
{
    size_t involved = 0, slipping = 0;
    for (size_t i = 0; i < c->n; ++i) {
        if (s->slipping[i] > 1 || s->involved[i] > 1 || (s->slipping[i] && !s->involved[i]))
            return BK_ERR_INVALID;
        involved += s->involved[i];
        slipping += s->slipping[i];
    }
    if (!s->open != !involved || (s->pending && slipping > 0) || (!s->pending && s->open && slipping == 0) ||
        (s->open && (s->first_block < 0 || (size_t)s->first_block >= c->n)))
        return BK_ERR_INVALID;
    int32_t *list = bk_grow_array(c->involved, &c->involved_capacity, involved ? involved : 1,
                                  sizeof *list, 64);
    if (!list)
        return BK_ERR_NOMEM;
    c->involved = list;
    c->serial++;
    c->n_involved = 0;
    c->n_slipping = slipping;
    for (size_t i = 0; i < c->n; ++i) {
        c->slipping[i] = (int8_t)s->slipping[i];
        c->x_onset[i] = s->x_onset[i];
        c->first_force[i] = s->first_force[i];
        c->last_force[i] = s->last_force[i];
        c->seen[i] = s->involved[i] ? c->serial : -1;
        if (s->involved[i])
            c->involved[c->n_involved++] = (int32_t)i;
    }
    c->open = s->open != 0;
    c->pending = s->pending != 0;
    c->t_pending = s->t_pending;
    c->event = (bk_event){.t_start = s->t_start,
                          .first_block = (int32_t)s->first_block,
                          .n_episodes = (int32_t)s->n_episodes,
                          .potency = s->potency,
                          .max_slip_rate = s->max_slip_rate,
                          .complete = 1};
    return BK_OK;
}
