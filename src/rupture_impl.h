/* Internal: the rupture builder's state, shared by the files that build the rupture catalog
 * (bksim/rupture.h), listed in the order they call one another, top first: rupture.c (the
 * builder: links, completes and emits ruptures), rupture_save.c (checkpoints),
 * rupture_rate.c (speed samples and their sum, the moment rate), rupture_pool.c (the pools of
 * episodes, ruptures and traces, and the union-find over ruptures); rupture_front.c (front
 * speeds) needs none of this state. */
#ifndef BKSIM_RUPTURE_IMPL_H
#define BKSIM_RUPTURE_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/rupture.h"

/* No episode, rupture node or trace. */
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
    int32_t node;            /* a rupture node it belongs to (bk_rupture_find: the root) */
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

/* ---- rupture_rate.c ---- */
/* A speed sample of episode e at t: those after t are dropped (a trajectory the run
 * discarded), one at t replaced; the rupture's settled samples are summed into its rate once
 * enough are held. */
int bk_rupture_push_sample(bk_ruptures *b, int32_t e, double t, double speed);
/* Sum root r's traces up to W into its rate and trim them there (W = +inf: everything, the
 * rupture has ended). */
int bk_rupture_fold(bk_ruptures *b, int32_t r, double W);

/* ---- rupture_pool.c ---- */
/* A fresh episode, rupture node or trace (a sum: stride 4) from its pool, buffers reused;
 * NONE when out of memory.  new_trace may move b->traces, never b->nodes or b->episodes. */
int32_t bk_rupture_new_episode(bk_ruptures *b);
int32_t bk_rupture_new_node(bk_ruptures *b);
int32_t bk_rupture_new_trace(bk_ruptures *b);
void bk_rupture_release_episode(bk_ruptures *b, int32_t e);
void bk_rupture_release_trace(bk_ruptures *b, int32_t k);
/* Empty a trace, keeping its buffer unless it grew long. */
void bk_rupture_trace_clear(trace *tr);
/* The root of rupture node r (path compression). */
int32_t bk_rupture_find(bk_ruptures *b, int32_t r);
/* Episode e at the end of root's list. */
void bk_rupture_append_episode(bk_ruptures *b, int32_t root, int32_t e);
/* Root `from` joins root `into`; BK_ERR_NOMEM when its rate cannot be kept. */
int bk_rupture_merge(bk_ruptures *b, int32_t into, int32_t from);

#endif
