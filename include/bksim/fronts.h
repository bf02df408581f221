/* Fronts on a chain loaded from one edge (bksim fronts): for each rupture, how far from the
 * loaded edge it got (its arrest length), whether it crossed the chain, its mean front speed,
 * and the force the edge was loaded with when it began: the precursor table of Rubinstein,
 * Cohen and Fineberg's experiments and of the 1D spring-block models (Trømborg et al. 2011,
 * Amundsen et al. 2012/2015, Thøgersen et al. 2019); and the speed of one rupture's front
 * block by block.  From the rupture catalog (bksim/rupture.h): no HDF5 here. */
#ifndef BKSIM_FRONTS_H
#define BKSIM_FRONTS_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/model.h"
#include "bksim/rupture.h"
#include "bksim/sink.h"
#include "bksim/status.h"

typedef struct bk_front {
    int64_t rupture;        /* row of /ruptures */
    double t_start;         /* s */
    double edge_force;      /* N: the loaded edge block's driver-spring and applied force at
                               t_start (NaN when not known) */
    int32_t first_block;    /* the epicentre */
    int32_t n_blocks;
    int32_t arrest_length;  /* blocks: from the loaded edge to the farthest block reached, both
                               counted (the chain's length when it crossed) */
    int8_t from_edge;       /* it started at the loaded edge block */
    int8_t crossed;         /* it reached the far edge block */
    double mean_speed;      /* blocks/s: least-squares slope of distance from the loaded edge
                               against arrival time over its blocks; NaN with fewer than 3,
                               inf when all arrive at once */
    double duration;        /* s */
} bk_front;

/* One row per rupture of a chain of n_blocks (rows of blocks in block order per rupture, as
 * /rupture_blocks holds them), the loaded edge at block 0 (edge_right = 0) or n_blocks - 1;
 * edge_force may be NULL (NaN then), else one value per rupture.  out has n_ruptures rows.
 * BK_ERR_INVALID when a block row names no rupture or a block outside the chain. */
int bk_fronts(const bk_rupture *ruptures, size_t n_ruptures, const bk_rupture_block *blocks, size_t n_rows,
              size_t n_blocks, int edge_right, const double *edge_force, bk_front *out, bk_error *err);

/* The force the loaded edge block is pushed with when each rupture begins: its driver spring's
 * (k (D(t) - x), from the driver's schedule and the block's position at its last transition,
 * /transitions in time order, or x_init before any) plus its applied_force; NaN for a rupture
 * that begins while the edge block slips in another (its position then is not in the table;
 * at t = 0 it is x_init).  force has
 * n_ruptures entries (ruptures in any order: /ruptures lists them as they complete).
 * BK_ERR_NOMEM, or BK_OK. */
int bk_fronts_edge_force(const bk_model *model, const bk_transition *transitions, size_t n_transitions,
                         const bk_rupture *ruptures, size_t n_ruptures, int edge_right, double *force,
                         bk_error *err);

/* The front of one rupture block by block: for each of its blocks (count rows of one rupture,
 * in block order), its distance from the loaded edge and the local front speed there, the
 * least-squares slope of distance against arrival time over the blocks within window/2 of it
 * (window >= 2 blocks; NaN with fewer than 3 blocks in reach or no spread in time, inf when
 * they all arrive at once).  distance and speed have count entries. */
int bk_front_profile(const bk_rupture_block *blocks, size_t count, size_t n_blocks, int edge_right, size_t window,
                     double *distance, double *speed, bk_error *err);

#endif
