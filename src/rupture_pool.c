/* The rupture builder's pools (rupture_impl.h): episodes, rupture nodes and traces, reused
 * with their buffers, and the union-find over rupture nodes whose roots are the open
 * ruptures. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capacity.h"
#include "rupture_impl.h"

int32_t bk_rupture_new_episode(bk_ruptures *b)
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
void bk_rupture_trace_clear(trace *tr)
{
    if (tr->capacity > 256) {
        free(tr->samples);
        tr->samples = NULL;
        tr->capacity = 0;
    }
    tr->n = 0;
}

int32_t bk_rupture_new_trace(bk_ruptures *b)
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

void bk_rupture_release_trace(bk_ruptures *b, int32_t k)
{
    bk_rupture_trace_clear(&b->traces[k]);
    b->traces[k].next = b->free_trace;
    b->free_trace = k;
}

void bk_rupture_release_episode(bk_ruptures *b, int32_t e)
{
    episode *ep = &b->episodes[e];
    if (b->latest[ep->block] == e)
        b->latest[ep->block] = NONE;
    bk_rupture_trace_clear(&ep->speed);
    ep->next = b->free_episode;
    b->free_episode = e;
}

int32_t bk_rupture_new_node(bk_ruptures *b)
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

int32_t bk_rupture_find(bk_ruptures *b, int32_t r)
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

void bk_rupture_append_episode(bk_ruptures *b, int32_t root, int32_t e)
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
int bk_rupture_merge(bk_ruptures *b, int32_t into, int32_t from)
{
    if (b->nodes[from].rate.n > 0) {
        int32_t k = bk_rupture_new_trace(b); /* may move b->traces, never b->nodes */
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

