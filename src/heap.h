/* Internal: an indexed binary min-heap of items 0..capacity-1 keyed by doubles, with O(log n)
 * insert, update, remove and pop, and O(1) lookup of an item's key.  The run loop keeps two:
 * the failure times of quiet stuck blocks and the next event times of the islands. */
#ifndef BKSIM_HEAP_H
#define BKSIM_HEAP_H

#include <stddef.h>

/* Keys sit beside their items in heap order, so a sift compares neighbouring memory
 * instead of fetching each key from wherever its item is (a long chain's queues hold 1e5
 * items). */
typedef struct bk_heap_entry {
    double key;
    size_t item;
} bk_heap_entry;

typedef struct bk_heap {
    bk_heap_entry *entries; /* heap order */
    size_t *position;       /* per item: its index in entries, or BK_HEAP_ABSENT */
    size_t count, capacity;
} bk_heap;

#define BK_HEAP_ABSENT ((size_t)-1)

/* Room for items 0..capacity-1; -1 when out of memory. */
int bk_heap_init(bk_heap *heap, size_t capacity);
/* Grow to hold items 0..capacity-1 (never shrinks); -1 when out of memory. */
int bk_heap_reserve(bk_heap *heap, size_t capacity);
void bk_heap_free(bk_heap *heap);
void bk_heap_clear(bk_heap *heap);

/* Insert item with key, or move it to key when present. */
void bk_heap_set(bk_heap *heap, size_t item, double key);
void bk_heap_remove(bk_heap *heap, size_t item);
static inline int bk_heap_contains(const bk_heap *heap, size_t item)
{
    return item < heap->capacity && heap->position[item] != BK_HEAP_ABSENT;
}
static inline int bk_heap_empty(const bk_heap *heap) { return heap->count == 0; }
/* The item with the smallest key (ties: the smaller item) and that key; heap not empty. */
static inline size_t bk_heap_top(const bk_heap *heap) { return heap->entries[0].item; }
static inline double bk_heap_top_key(const bk_heap *heap) { return heap->entries[0].key; }
/* Remove and return the top item. */
size_t bk_heap_pop(bk_heap *heap);

#endif
