/* The nodes output rows are interpolated through (hermite.h) for a back-end without dense
 * output of its own: the last step's ends, older step ends of the same integration (y and f
 * are known there, so they cost nothing), and nodes inside the step that the back-end adds
 * by re-stepping where the polynomial's error estimate is too large. */
#ifndef BKSIM_SOLVER_ROW_NODES_H
#define BKSIM_SOLVER_ROW_NODES_H

#include <stddef.h>

#include "solver/hermite.h"

#define BK_ROW_HISTORY (BK_HERMITE_MAX_NODES - 2)
#define BK_ROW_INNER (BK_HERMITE_MAX_NODES - 2)

typedef struct bk_row_nodes {
    size_t n, capacity;
    double *arena;
    size_t n_history;                         /* older step ends held, newest first */
    double history_t[BK_ROW_HISTORY];
    double *history_y[BK_ROW_HISTORY], *history_f[BK_ROW_HISTORY];
    size_t n_inner;                           /* nodes inside the step */
    double inner_t[BK_ROW_INNER];
    double *inner_y[BK_ROW_INNER], *inner_f[BK_ROW_INNER];
    size_t want;                              /* nodes the polynomial should have */
    double lo, hi;                            /* the step it is built for (NAN: none) */
    const double *end_y[2], *end_f[2];        /* y and f at lo and hi, the back-end's */
    bk_hermite poly;
} bk_row_nodes;

/* A new integration of n components: room for its nodes, nothing remembered; -1 when out
 * of memory. */
int bk_row_nodes_start(bk_row_nodes *r, size_t n);
void bk_row_nodes_free(bk_row_nodes *r);
/* The start (t, y, f) of a step about to be replaced by the next becomes an older node. */
void bk_row_nodes_push(bk_row_nodes *r, double t, const double *y, const double *f);
/* The polynomial for the step [lo, hi] (ends given by y and f, which must stay valid while
 * the step lasts), built unless it is already: the ends, the nodes inside the step, then
 * older step ends not closer than 1/8 of the step to the next, up to want nodes. */
void bk_row_nodes_prepare(bk_row_nodes *r, size_t want, double lo, const double *y_lo,
                          const double *f_lo, double hi, const double *y_hi, const double *f_hi);
/* Room for a node inside the step: its y and f arrays (n each), or 0 when the step has
 * all it may have. */
int bk_row_nodes_inner(bk_row_nodes *r, double **y, double **f);
/* The node just filled (at t, inside the step) joins the polynomial. */
void bk_row_nodes_add_inner(bk_row_nodes *r, double t);

#endif
