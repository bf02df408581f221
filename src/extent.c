/* The extent of a set of blocks (extent.h). */
#include "extent.h"

#include <stdlib.h>

#include "capacity.h"

static int compare_blocks(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* The first and last of k distinct sorted lines along a direction of len lines: on a ring
 * the shorter arc covering them, the complement of the widest gap between two of them. */
static void span(const int32_t *line, size_t k, size_t len, int ring, int32_t *first, int32_t *last)
{
    *first = line[0];
    *last = line[k - 1];
    if (!ring || k == 1)
        return;
    /* The gap after the last line wraps round to the first. */
    int64_t widest = (int64_t)len - line[k - 1] + line[0];
    for (size_t j = 1; j < k; ++j) {
        int64_t gap = (int64_t)line[j] - line[j - 1];
        if (gap > widest) {
            widest = gap;
            *first = line[j];
            *last = line[j - 1];
        }
    }
}

/* Sort and drop repeats; returns the count left. */
static size_t distinct(int32_t *values, size_t k)
{
    qsort(values, k, sizeof *values, compare_blocks);
    size_t kept = 0;
    for (size_t j = 0; j < k; ++j)
        if (kept == 0 || values[j] != values[kept - 1])
            values[kept++] = values[j];
    return kept;
}

int bk_extent(size_t rows, size_t cols, int ring_rows, int ring_cols, int32_t *blocks, size_t k,
              int32_t **scratch, size_t *scratch_capacity, int32_t *left, int32_t *right)
{
    qsort(blocks, k, sizeof *blocks, compare_blocks);
    if (rows == 1) {
        span(blocks, k, cols, ring_cols, left, right);
        return 0;
    }
    int32_t *lines = bk_grow_array(*scratch, scratch_capacity, k, sizeof *lines, 64);
    if (!lines)
        return -1;
    *scratch = lines;
    int32_t n_cols = (int32_t)cols, row_first, row_last, col_first, col_last;
    for (size_t j = 0; j < k; ++j)
        lines[j] = blocks[j] / n_cols;
    span(lines, distinct(lines, k), rows, ring_rows, &row_first, &row_last);
    for (size_t j = 0; j < k; ++j)
        lines[j] = blocks[j] % n_cols;
    span(lines, distinct(lines, k), cols, ring_cols, &col_first, &col_last);
    *left = row_first * n_cols + col_first;
    *right = row_last * n_cols + col_last;
    return 0;
}
