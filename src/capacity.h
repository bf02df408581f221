/* Internal: when reused buffers are reallocated.  Islands and solver instances are reused;
 * one that once served a large island must not keep that memory for small ones, or a long
 * run's memory would follow the largest islands it ever had instead of the chain. */
#ifndef BKSIM_CAPACITY_H
#define BKSIM_CAPACITY_H

#include <stddef.h>

/* A buffer of cap elements serves a need: large enough, and not four times too large
 * (small buffers are kept whatever the need: reallocating them would cost more). */
static inline int bk_capacity_fits(size_t need, size_t cap)
{
    return need <= cap && (cap <= 8 || need >= cap / 2);
}

#endif
