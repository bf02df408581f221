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
    bk_heap_entry *entries = realloc(heap->entries, capacity * sizeof *entries);
    if (!entries)
        return -1;
    heap->entries = entries;
    size_t *position = realloc(heap->position, capacity * sizeof *position);
    if (!position)
        return -1;
    heap->position = position;
    for (size_t i = heap->capacity; i < capacity; ++i)
        heap->position[i] = BK_HEAP_ABSENT;
    heap->capacity = capacity;
    return 0;
}

void bk_heap_free(bk_heap *heap)
{
    free(heap->entries);
    free(heap->position);
    memset(heap, 0, sizeof *heap);
}

void bk_heap_clear(bk_heap *heap)
{
    for (size_t k = 0; k < heap->count; ++k)
        heap->position[heap->entries[k].item] = BK_HEAP_ABSENT;
    heap->count = 0;
}

static int before(bk_heap_entry a, bk_heap_entry b)
{
    return a.key < b.key || (a.key == b.key && a.item < b.item);
}

static void place(bk_heap *heap, size_t index, bk_heap_entry entry)
{
    heap->entries[index] = entry;
    heap->position[entry.item] = index;
}

static void sift_up(bk_heap *heap, size_t index)
{
    bk_heap_entry entry = heap->entries[index];
    while (index > 0) {
        size_t parent = (index - 1) / 2;
        if (!before(entry, heap->entries[parent]))
            break;
        place(heap, index, heap->entries[parent]);
        index = parent;
    }
    place(heap, index, entry);
}

static void sift_down(bk_heap *heap, size_t index)
{
    bk_heap_entry entry = heap->entries[index];
    for (;;) {
        size_t child = 2 * index + 1;
        if (child >= heap->count)
            break;
        if (child + 1 < heap->count && before(heap->entries[child + 1], heap->entries[child]))
            ++child;
        if (!before(heap->entries[child], entry))
            break;
        place(heap, index, heap->entries[child]);
        index = child;
    }
    place(heap, index, entry);
}

void bk_heap_set(bk_heap *heap, size_t item, double key)
{
    size_t index = heap->position[item];
    if (index == BK_HEAP_ABSENT) {
        index = heap->count++;
        place(heap, index, (bk_heap_entry){key, item});
        sift_up(heap, index);
        return;
    }
    heap->entries[index].key = key;
    sift_up(heap, index);
    sift_down(heap, heap->position[item]);
}

void bk_heap_remove(bk_heap *heap, size_t item)
{
    size_t index = heap->position[item];
    if (index == BK_HEAP_ABSENT)
        return;
    heap->position[item] = BK_HEAP_ABSENT;
    bk_heap_entry last = heap->entries[--heap->count];
    if (index == heap->count)
        return;
    place(heap, index, last);
    sift_up(heap, index);
    sift_down(heap, heap->position[last.item]);
}

size_t bk_heap_pop(bk_heap *heap)
{
    size_t top = heap->entries[0].item;
    bk_heap_remove(heap, top);
    return top;
}
