/* The rupture catalog: ruptures built from the stream of block transitions, with the blocks
 * each one moved and its moment-rate function.
 *
 * A slip episode of block i runs from an onset (stick -> slip) to the next stop (slip ->
 * stick); a reversal continues it.  For a law without a stuck state the run loop passes the
 * crossings of [catalog] slip_rate_threshold as the onsets and stops.  Two episodes (block i
 * over [a, b], block j over [c, d]) are linked when i and j are the same block or neighbours
 * in the coupling graph (chain, ring or lattice, as the model couples them) and the closed
 * intervals meet, max(a, c) <= min(b, d).  A rupture is a connected component of linked
 * episodes.  So two fronts that meet are one rupture, and a neighbour that starts after a
 * block stopped (later, not at the same instant) starts a new one.
 *
 * The builder sees each transition once, in time order, and costs O(1) amortised per
 * transition and per rate sample; a rupture costs O(E log E) when it completes (E its
 * episodes, plus its samples); memory is what the open ruptures hold plus a few words per
 * block: never a pass over the chain. */
#ifndef BKSIM_RUPTURE_H
#define BKSIM_RUPTURE_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/sink.h"

typedef struct bk_rupture {
    double t_start, t_end;   /* s: its first onset, its last stop (the run's end if open) */
    int32_t first_block;     /* the epicentre: the block of the earliest onset (lowest index
                                on a tie) */
    int32_t n_blocks;        /* distinct blocks */
    int32_t left, right;     /* extent, as bk_event's: on a ring the shorter covering arc
                                (left > right when it wraps); on a lattice the bounding
                                box's top-left and bottom-right corners */
    int32_t n_episodes;
    double potency;          /* m: sum over its episodes of x at stop - x at onset (a slip back
                                counts negative: the moment-rate function, a sum of |v|,
                                integrates to the potency when no episode slips back) */
    double magnitude;        /* (2/3) log10(potency / 1 m) + magnitude_offset; -inf if <= 0 */
    double max_slip_rate;    /* m/s: the largest |v| of any of its blocks while slipping */
    double stress_drop;      /* N: mean over its blocks of the applied force at the first
                                onset minus that at the last stop */
    double duration;         /* s: t_end - t_start */
    double front_speed_left, front_speed_right; /* blocks/s: see bk_rupture_front_speeds */
    int8_t complete;         /* 0: some episode still ran at the end of the run */
} bk_rupture;

/* One block of a rupture (rows in block order within each rupture). */
typedef struct bk_rupture_block {
    int64_t rupture;         /* row of /ruptures */
    int32_t block;
    double t_onset;          /* s: its first onset in the rupture (the front's arrival) */
    double t_stop;           /* s: its last stop (the run's end if still slipping) */
    double slip;             /* m: its net displacement while slipping in the rupture: the sum
                                over its episodes of x at stop - x at onset (another rupture's
                                slip of the block in between is not counted) */
} bk_rupture_block;

/* One sample of a rupture's moment-rate (potency-rate) function: the sum over its slipping
 * blocks of |v|. */
typedef struct bk_rupture_rate {
    int64_t rupture;         /* row of /ruptures */
    double t;                /* s */
    double rate;             /* m/s */
} bk_rupture_rate;

/* Where a completed rupture goes: its row, its blocks (n_blocks rows) and its rate samples
 * (n_rate rows; none when the builder keeps no rate).  Non-zero stops the builder. */
typedef int (*bk_rupture_emit_fn)(void *user, const bk_rupture *rupture,
                                  const bk_rupture_block *blocks, size_t n_blocks,
                                  const bk_rupture_rate *rate, size_t n_rate);
/* The applied (driver plus coupling) force on block i, N. */
typedef double (*bk_rupture_force_fn)(const void *user, size_t i);

typedef struct bk_ruptures bk_ruptures;

/* A builder for a rows x cols lattice (a chain: 1 x n), each direction a ring or not, with
 * the magnitude offset; keep_rate: write rate samples (else only their maximum is kept).
 * NULL when out of memory. */
bk_ruptures *bk_ruptures_create(size_t rows, size_t cols, int ring_rows, int ring_cols,
                                double magnitude_offset, int keep_rate, bk_rupture_emit_fn emit,
                                void *emit_user);
void bk_ruptures_free(bk_ruptures *builder);

/* Blocks slipping at the start t (slipping[i] != 0) open episodes, with their positions,
 * velocities (may be NULL: at rest) and forces.  Once, before the first transition. */
int bk_ruptures_begin(bk_ruptures *builder, double t, const uint8_t *slipping, const double *x,
                      const double *v, bk_rupture_force_fn force, const void *user);
/* One transition (in time order).  Ruptures that no later transition can extend (this one
 * comes after their last stop) are emitted first, by t_start then first_block.  Returns
 * BK_OK, BK_ERR_NOMEM, BK_ERR_INVALID (block out of range) or the emitter's non-zero code. */
int bk_ruptures_add(bk_ruptures *builder, const bk_transition *transition);
/* Whether block i slips in an open episode now. */
int bk_ruptures_slipping(const bk_ruptures *builder, size_t i);
/* The largest |v| block i's open episode has seen so far; -1 when it has none. */
double bk_ruptures_episode_peak(const bk_ruptures *builder, size_t i);
/* |v| of block i (slipping) at t, from the back-end's dense output: a sample of its rate.  A
 * sample at t drops those after t (a trajectory the run discarded when it restarted the
 * block's island at t) and replaces one at t.  Ignored when block i does not slip. */
int bk_ruptures_sample(bk_ruptures *builder, size_t i, double t, double speed);
/* Block i's speed samples up to t are final (no restart can drop them any more: its
 * island's integrator has stepped past t), so they may be summed into its rupture's rate. */
void bk_ruptures_settle(bk_ruptures *builder, size_t i, double t);
/* The end of the run at t, with every block's position and velocity (v may be NULL):
 * ruptures pending are emitted complete, those still running with complete = 0 and their
 * open episodes counted to t. */
int bk_ruptures_finish(bk_ruptures *builder, double t, const double *x, const double *v,
                       bk_rupture_force_fn force, const void *user);
/* Ruptures emitted so far, and rows of blocks and of rate samples. */
void bk_ruptures_counts(const bk_ruptures *builder, long *ruptures, long *block_rows,
                        long *rate_rows);

/* What a checkpoint keeps: the open ruptures and the counts, as doubles (every integer held
 * exactly).  bk_ruptures_save returns the values needed (call with capacity 0 to size the
 * buffer) and writes them when capacity allows; restore refuses values that do not hold
 * together (BK_ERR_INVALID) or BK_ERR_NOMEM. */
size_t bk_ruptures_save(const bk_ruptures *builder, double *values, size_t capacity);
int bk_ruptures_restore(bk_ruptures *builder, const double *values, size_t count);
/* The counts saved values hold (ruptures emitted, rows of /rupture_blocks and of
 * /rupture_rate), without a builder; BK_ERR_INVALID when they are no builder's state. */
int bk_ruptures_saved_counts(const double *values, size_t count, long *ruptures, long *block_rows,
                             long *rate_rows);

/* The front speeds of a rupture from its blocks' arrival times (t_onset), blocks per second:
 * a least-squares fit of arrival time against distance from the epicentre on each side, the
 * epicentre included (distance 0) and NaN with fewer than 3 points on a side; +inf when
 * every arrival on the side is simultaneous, NaN when the fit's slope is negative.  On a ring
 * distance goes the shorter way round; on a lattice it is radial, the left side the blocks
 * whose column is left of the epicentre's, the right side those right of it, and the
 * epicentre's own column split by row (above: left; below: right), so that a lattice of one
 * column reads as a chain.
 * Exposed for tests and readers of /rupture_blocks. */
void bk_rupture_front_speeds(const bk_rupture_block *blocks, size_t n, int32_t epicentre,
                             size_t rows, size_t cols, int ring_rows, int ring_cols, double *left,
                             double *right);

#endif
