/* Hermite interpolation through a few nodes where both y and y' are known: the dense output
 * the GSL back-ends give output rows, built from the ends of the last steps (and, where
 * those are too few or too close together, from nodes inside the step) at no cost in steps.
 * Through k nodes the polynomial has degree 2k - 1 and its error is
 * y^(2k)(xi) / (2k)! * prod (t - t_j)^2. */
#ifndef BKSIM_SOLVER_HERMITE_H
#define BKSIM_SOLVER_HERMITE_H

#include <stddef.h>

#define BK_HERMITE_MAX_NODES 6

typedef struct bk_hermite {
    size_t n;                             /* components */
    size_t capacity;                      /* components c has room for */
    size_t m;                             /* 2 x nodes of the polynomial built (0: none) */
    double z[2 * BK_HERMITE_MAX_NODES];   /* its abscissae, each node twice */
    double *c;                            /* Newton coefficients, m per component */
} bk_hermite;

/* Set up for n components (reallocating only to grow); -1 when out of memory. */
int bk_hermite_reserve(bk_hermite *h, size_t n);
void bk_hermite_free(bk_hermite *h);
/* The polynomial through the k nodes t[j] (distinct) with values y[j] and derivatives f[j]
 * (arrays of n); 1 <= k <= BK_HERMITE_MAX_NODES. */
void bk_hermite_build(bk_hermite *h, size_t k, const double *t, const double *const *y,
                      const double *const *f);
/* The polynomial at t into out (n values); tail (NULL or n values) receives the last
 * node's share of it, the difference from the polynomial through the other nodes: an
 * estimate of the error, on the safe side. */
void bk_hermite_eval(const bk_hermite *h, double t, double *out, double *tail);

#endif
