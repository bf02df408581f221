/* Indexed binary min-heap (see heap.h).  Ties break on the item number, so the order in
 * which equal keys come out does not depend on the order they went in: a resumed run
 * rebuilds its heaps from scratch and must pop exactly what the uninterrupted run pops. */
#include "heap.h"

#include <stdlib.h>
#include <string.h>

int bk_heap_init(bk_heap *heap, size_t capacity)
{
    memset(heap, 0, sizeof *heap);
    return bk_heap_reserve(heap, capacity);
}

int bk_heap_reserve(bk_heap *heap, size_t capacity)
{
    if (capacity <= heap->capacity)
        return 0;
    size_t *items = realloc(heap->items, capacity * sizeof *items);
    if (!items)
        return -1;
    heap->items = items;
    size_t *position = realloc(heap->position, capacity * sizeof *position);
    if (!position)
        return -1;
    heap->position = position;
    double *key = realloc(heap->key, capacity * sizeof *key);
    if (!key)
        return -1;
    heap->key = key;
    for (size_t i = heap->capacity; i < capacity; ++i)
        heap->position[i] = BK_HEAP_ABSENT;
    heap->capacity = capacity;
    return 0;
}

void bk_heap_free(bk_heap *heap)
{
    free(heap->items);
    free(heap->position);
    free(heap->key);
    memset(heap, 0, sizeof *heap);
}

void bk_heap_clear(bk_heap *heap)
{
    for (size_t k = 0; k < heap->count; ++k)
        heap->position[heap->items[k]] = BK_HEAP_ABSENT;
    heap->count = 0;
}

static int before(const bk_heap *heap, size_t a, size_t b)
{
    double ka = heap->key[a], kb = heap->key[b];
    return ka < kb || (ka == kb && a < b);
}

static void place(bk_heap *heap, size_t index, size_t item)
{
    heap->items[index] = item;
    heap->position[item] = index;
}

static void sift_up(bk_heap *heap, size_t index)
{
    size_t item = heap->items[index];
    while (index > 0) {
        size_t parent = (index - 1) / 2;
        if (!before(heap, item, heap->items[parent]))
            break;
        place(heap, index, heap->items[parent]);
        index = parent;
    }
    place(heap, index, item);
}

static void sift_down(bk_heap *heap, size_t index)
{
    size_t item = heap->items[index];
    for (;;) {
        size_t child = 2 * index + 1;
        if (child >= heap->count)
            break;
        if (child + 1 < heap->count && before(heap, heap->items[child + 1], heap->items[child]))
            ++child;
        if (!before(heap, heap->items[child], item))
            break;
        place(heap, index, heap->items[child]);
        index = child;
    }
    place(heap, index, item);
}

void bk_heap_set(bk_heap *heap, size_t item, double key)
{
    size_t index = heap->position[item];
    heap->key[item] = key;
    if (index == BK_HEAP_ABSENT) {
        index = heap->count++;
        place(heap, index, item);
        sift_up(heap, index);
        return;
    }
    sift_up(heap, index);
    sift_down(heap, heap->position[item]);
}

void bk_heap_remove(bk_heap *heap, size_t item)
{
    size_t index = heap->position[item];
    if (index == BK_HEAP_ABSENT)
        return;
    heap->position[item] = BK_HEAP_ABSENT;
    size_t last = heap->items[--heap->count];
    if (index == heap->count)
        return;
    place(heap, index, last);
    sift_up(heap, index);
    sift_down(heap, heap->position[last]);
}

size_t bk_heap_pop(bk_heap *heap)
{
    size_t top = heap->items[0];
    bk_heap_remove(heap, top);
    return top;
}
