/* The event catalog: slip events built from the stream of block transitions.
 *
 * An event is a maximal time interval during which at least one block slips.  Two ruptures
 * that overlap in time are one event wherever they are on the chain; a block that sticks at
 * the very instant another starts (transitions at the same time) keeps the event going.
 * The builder sees each transition once, in time order (within an instant in any order),
 * and costs O(1) per transition plus O(blocks involved) when an event ends: nothing here
 * scales with the chain. */
#ifndef BKSIM_CATALOG_H
#define BKSIM_CATALOG_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/run.h"

typedef struct bk_event {
    double t_start, t_end;   /* s: first slip onset, last stick (t_end of the run if open) */
    int32_t first_block;     /* the epicentre: the first block to slip (lowest index if several) */
    int32_t n_blocks;        /* distinct blocks that slipped */
    int32_t left, right;     /* extent, blocks left..right; on a ring the shorter arc that
                                covers them, so left > right when it wraps past block 0 */
    int32_t n_episodes;      /* slip episodes (a block that slips twice counts twice) */
    double potency;          /* m: sum over episodes of |x at stick - x at slip onset| */
    double magnitude;        /* (2/3) log10(potency / 1 m) + magnitude_offset; -inf if 0 */
    double stress_drop;      /* N: mean over the blocks of the applied force at their first
                                onset minus that at their last stick */
    int8_t complete;         /* 0: still running at the end of the run */
} bk_event;

typedef struct bk_catalog bk_catalog;

/* A builder for n_blocks blocks (ring: periodic boundary) with the magnitude offset; NULL
 * when out of memory. */
bk_catalog *bk_catalog_create(size_t n_blocks, int ring, double magnitude_offset);
void bk_catalog_free(bk_catalog *catalog);
/* The applied (driver plus coupling) force on block i, N. */
typedef double (*bk_catalog_force_fn)(const void *user, size_t i);

/* Blocks already slipping at the start (t, every block's mode and position): they open an
 * event.  Call once before the first transition. */
int bk_catalog_begin(bk_catalog *catalog, double t, const int8_t *mode, const double *x,
                     bk_catalog_force_fn force, const void *user);
/* One transition; *done is set to 1 and *event filled when it completes an event that no
 * later transition can extend (its time is past the event's end).  The caller handles a
 * completed event before passing the next transition. */
int bk_catalog_add(bk_catalog *catalog, const bk_transition *transition, bk_event *event,
                   int *done);
/* The end of the run at t, with every block's position there: an event
 * whose end was pending is completed; one still running is returned with complete = 0,
 * its open slip episodes counted up to t.  Returns 1 when it wrote an event, else 0. */
int bk_catalog_finish(bk_catalog *catalog, double t, const double *x, bk_catalog_force_fn force,
                      const void *user, bk_event *event);

#endif
