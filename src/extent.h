/* Internal: where a set of blocks lies on the chain or lattice, shared by the event and the
 * rupture catalogs. */
#ifndef BKSIM_EXTENT_H
#define BKSIM_EXTENT_H

#include <stddef.h>
#include <stdint.h>

/* The extent of k distinct blocks (sorted here) of a rows x cols lattice (a chain: 1 x n),
 * each direction a ring or not: on a chain the first and last block (on a ring the shorter
 * arc covering them, left > right when it wraps); on a lattice the bounding box, left its
 * top-left corner and right its bottom-right one (each direction's span taken as a chain's).
 * scratch holds k values (a lattice only; *scratch grown with capacity *scratch_capacity).
 * Returns -1 when out of memory. */
int bk_extent(size_t rows, size_t cols, int ring_rows, int ring_cols, int32_t *blocks, size_t k,
              int32_t **scratch, size_t *scratch_capacity, int32_t *left, int32_t *right);

#endif
