/* The event catalog: slip events built from the stream of block transitions.
 *
 * An event is a maximal time interval during which at least one block slips.  Two ruptures
 * that overlap in time are one event wherever they are on the chain; a block that sticks at
 * the very instant another starts (transitions at the same time) keeps the event going.
 * For a law without a stuck state "slips" means "slip rate above a threshold", and the run
 * loop passes the threshold crossings as transitions (to = stick below it).
 * The builder sees each transition once, in time order (within an instant in any order),
 * and costs O(1) per transition plus O(blocks involved) when an event ends: nothing here
 * scales with the chain. */
#ifndef BKSIM_CATALOG_H
#define BKSIM_CATALOG_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/sink.h"

typedef struct bk_event {
    double t_start, t_end;   /* s: first slip onset, last stick (t_end of the run if open) */
    int32_t first_block;     /* the epicentre: the first block to slip (lowest index if several) */
    int32_t n_blocks;        /* distinct blocks that slipped */
    int32_t left, right;     /* extent, blocks left..right; on a ring the shorter arc that
                                covers them, so left > right when it wraps past block 0.  On
                                a lattice the bounding box: left its top-left corner, right
                                its bottom-right one (row = block / cols, column = block %
                                cols; each direction's span taken as a chain's) */
    int32_t n_episodes;      /* slip episodes (a block that slips twice counts twice) */
    double potency;          /* m: sum over episodes of |x at stick - x at slip onset| */
    double magnitude;        /* (2/3) log10(potency / 1 m) + magnitude_offset; -inf if 0 */
    double max_slip_rate;    /* m/s: the largest |v| of any block during the event */
    double stress_drop;      /* N: mean over the blocks of the applied force at their first
                                onset minus that at their last stick */
    int8_t complete;         /* 0: still running at the end of the run */
} bk_event;

typedef struct bk_catalog bk_catalog;

/* A builder for n_blocks blocks (ring: periodic boundary) with the magnitude offset; NULL
 * when out of memory. */
bk_catalog *bk_catalog_create(size_t n_blocks, int ring, double magnitude_offset);
/* The same for a rows x cols lattice, each direction a ring or not. */
bk_catalog *bk_catalog_create_lattice(size_t rows, size_t cols, int ring_rows, int ring_cols,
                                      double magnitude_offset);
void bk_catalog_free(bk_catalog *catalog);
/* The applied (driver plus coupling) force on block i, N. */
typedef double (*bk_catalog_force_fn)(const void *user, size_t i);

/* Blocks already slipping at the start (t, every block's mode, position and velocity; v
 * may be NULL): they open an event.  Call once before the first transition. */
int bk_catalog_begin(bk_catalog *catalog, double t, const int8_t *mode, const double *x,
                     const double *v, bk_catalog_force_fn force, const void *user);
/* One transition; *done is set to 1 and *event filled when it completes an event that no
 * later transition can extend (its time is past the event's end).  The caller handles a
 * completed event before passing the next transition.  A slip onset's |v| counts toward
 * the event's max_slip_rate. */
int bk_catalog_add(bk_catalog *catalog, const bk_transition *transition, bk_event *event,
                   int *done);
/* A slip rate (m/s, any sign) some block reached while the current event runs; ignored
 * when no block slips. */
void bk_catalog_slip_rate(bk_catalog *catalog, double slip_rate);
/* The largest |slip rate| of the current event so far; -1 when no block slips. */
double bk_catalog_max_slip_rate(const bk_catalog *catalog);
/* The end of the run at t, with every block's position there: an event
 * whose end was pending is completed; one still running is returned with complete = 0,
 * its open slip episodes counted up to t.  Returns 1 when it wrote an event, 0 when there
 * was none, BK_ERR_NOMEM when out of memory. */
int bk_catalog_finish(bk_catalog *catalog, double t, const double *x, bk_catalog_force_fn force,
                      const void *user, bk_event *event);

/* What a checkpoint keeps of a builder, so that a resumed run writes the same catalog.
 * Arrays have n_blocks entries; keep every scalar 8 bytes wide (the checkpoint's field
 * table describes this struct byte by byte). */
typedef struct bk_catalog_state {
    double *x_onset;      /* m, where each slipping block's current episode began */
    double *first_force;  /* N, at each involved block's first onset in the open event */
    double *last_force;   /* N, at its last stick */
    uint8_t *involved;    /* 1: the block slipped in the open event */
    uint8_t *slipping;    /* 1: the block slips now (for a law without a stuck state: above
                             the threshold) */
    long open, pending;   /* an event is open; nothing slips since t_pending */
    double t_pending;     /* s */
    double t_start;       /* s, of the open event */
    long first_block, n_episodes;
    double potency, max_slip_rate;
    long events;          /* events completed so far (rows of /events) */
    /* The rupture builder's open ruptures and counts (bk_ruptures_save), when the run keeps
     * them: rupture_state_count values, the count right after the pointer (the checkpoint's
     * table describes both as one variable-length field). */
    double *rupture_state;
    long rupture_state_count;
} bk_catalog_state;

/* Copy the builder's state out (arrays of the state allocated by the caller), or back in
 * (BK_ERR_INVALID when it does not hold together, e.g. a slipping block outside the open
 * event).  events is the caller's count; save leaves it alone. */
void bk_catalog_save(const bk_catalog *catalog, bk_catalog_state *state);
int bk_catalog_restore(bk_catalog *catalog, const bk_catalog_state *state);

#endif
