/* Output-row nodes (row_nodes.h). */
#include "solver/row_nodes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capacity.h"

/* A node closer than this fraction of the step to the next one is not used: close nodes
 * turn the steps' own errors into large errors of the polynomial's high derivatives. */
#define MIN_NODE_GAP 0.125

int bk_row_nodes_start(bk_row_nodes *r, size_t n)
{
    r->n_history = r->n_inner = 0;
    r->lo = r->hi = NAN;
    size_t arrays = 2 * BK_ROW_HISTORY + 2 * BK_ROW_INNER;
    if (!bk_capacity_fits(n, r->capacity) || !r->arena) {
        double *arena = malloc(arrays * (n ? n : 1) * sizeof *arena);
        if (!arena)
            return -1;
        free(r->arena);
        r->arena = arena;
        r->capacity = n;
        double *next = arena;
        for (size_t k = 0; k < BK_ROW_HISTORY; ++k, next += 2 * n) {
            r->history_y[k] = next;
            r->history_f[k] = next + n;
        }
        for (size_t k = 0; k < BK_ROW_INNER; ++k, next += 2 * n) {
            r->inner_y[k] = next;
            r->inner_f[k] = next + n;
        }
    }
    r->n = n;
    return bk_hermite_reserve(&r->poly, n);
}

void bk_row_nodes_free(bk_row_nodes *r)
{
    free(r->arena);
    bk_hermite_free(&r->poly);
    memset(r, 0, sizeof *r);
}

void bk_row_nodes_push(bk_row_nodes *r, double t, const double *y, const double *f)
{
    size_t last = BK_ROW_HISTORY - 1;
    double *y_slot = r->history_y[last], *f_slot = r->history_f[last];
    for (size_t k = last; k > 0; --k) {
        r->history_t[k] = r->history_t[k - 1];
        r->history_y[k] = r->history_y[k - 1];
        r->history_f[k] = r->history_f[k - 1];
    }
    r->history_t[0] = t;
    r->history_y[0] = y_slot;
    r->history_f[0] = f_slot;
    memcpy(y_slot, y, r->n * sizeof *y);
    memcpy(f_slot, f, r->n * sizeof *f);
    if (r->n_history < BK_ROW_HISTORY)
        r->n_history++;
}

static void build(bk_row_nodes *r)
{
    size_t k = 2;
    double h = r->hi - r->lo;
    double t[BK_HERMITE_MAX_NODES] = {r->lo, r->hi};
    const double *ys[BK_HERMITE_MAX_NODES] = {r->end_y[0], r->end_y[1]};
    const double *fs[BK_HERMITE_MAX_NODES] = {r->end_f[0], r->end_f[1]};
    for (size_t j = 0; j < r->n_inner; ++j, ++k) {
        t[k] = r->inner_t[j];
        ys[k] = r->inner_y[j];
        fs[k] = r->inner_f[j];
    }
    double oldest = r->lo;
    for (size_t j = 0; j < r->n_history && k < r->want; ++j, ++k) {
        if (oldest - r->history_t[j] < MIN_NODE_GAP * h)
            break;
        t[k] = oldest = r->history_t[j];
        ys[k] = r->history_y[j];
        fs[k] = r->history_f[j];
    }
    bk_hermite_build(&r->poly, k, t, ys, fs);
}

void bk_row_nodes_prepare(bk_row_nodes *r, size_t want, double lo, const double *y_lo,
                          const double *f_lo, double hi, const double *y_hi, const double *f_hi)
{
    if (r->lo == lo && r->hi == hi)
        return;
    r->want = want;
    r->lo = lo;
    r->hi = hi;
    r->end_y[0] = y_lo, r->end_y[1] = y_hi;
    r->end_f[0] = f_lo, r->end_f[1] = f_hi;
    r->n_inner = 0;
    build(r);
}

int bk_row_nodes_inner(bk_row_nodes *r, double **y, double **f)
{
    if (r->n_inner == BK_ROW_INNER)
        return 0;
    *y = r->inner_y[r->n_inner];
    *f = r->inner_f[r->n_inner];
    return 1;
}

void bk_row_nodes_add_inner(bk_row_nodes *r, double t)
{
    r->inner_t[r->n_inner++] = t;
    build(r);
}
