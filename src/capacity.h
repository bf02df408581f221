/* Internal: when buffers are reallocated.  Islands and solver instances are reused; one that
 * once served a large island must not keep that memory for small ones, or a long run's
 * memory would follow the largest islands it ever had instead of the chain.  Lists that
 * only grow (a table being filled) grow by doubling. */
#ifndef BKSIM_CAPACITY_H
#define BKSIM_CAPACITY_H

#include <stddef.h>
#include <stdlib.h>

/* A buffer of cap elements serves a need: large enough, and not four times too large
 * (small buffers are kept whatever the need: reallocating them would cost more). */
static inline int bk_capacity_fits(size_t need, size_t cap)
{
    return need <= cap && (cap <= 8 || need >= cap / 2);
}

/* buf if it fits need elements of size bytes (above), else a buffer of exactly need elements
 * in its place, contents dropped; NULL when out of memory, buf and *capacity left as they were. */
static inline void *bk_fit_buffer(void *buf, size_t *capacity, size_t need, size_t size)
{
    if (bk_capacity_fits(need, *capacity))
        return buf;
    void *fitted = malloc(need * size);
    if (!fitted)
        return NULL;
    free(buf);
    *capacity = need;
    return fitted;
}

/* items if they have room for need elements of size bytes, else the same items moved to a
 * block at least twice as large (first elements at the least); NULL when out of memory,
 * items and *capacity left as they were. */
static inline void *bk_grow_array(void *items, size_t *capacity, size_t need, size_t size,
                                  size_t first)
{
    if (need <= *capacity)
        return items;
    size_t cap = *capacity ? 2 * *capacity : first;
    if (cap < need)
        cap = need;
    void *grown = realloc(items, cap * size);
    if (grown)
        *capacity = cap;
    return grown;
}

#endif
