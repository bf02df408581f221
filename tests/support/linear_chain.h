/* A free-ended chain of p blocks of unequal mass and spring constants, each tied to the
 * ground, under a force that ramps in time: the affine problem the exact stepper solves,
 * with all p blocks in one non-uniform cluster (no root functions).  State: (x, v) pairs,
 * then two quadratures q0' = sum (c_i x_i + d_i v_i) + 1 + t / 2 and q1' = sum v_i.  Used by
 * the exact stepper's tests and bench/exact_rows.c. */
#ifndef BK_TEST_LINEAR_CHAIN_H
#define BK_TEST_LINEAR_CHAIN_H

#include <stddef.h>

#include "bksim/solver.h"

typedef struct linear_chain {
    size_t p;
    double *mass, *ground, *coupling; /* p, p, p - 1 */
    double *force, *force_rate;       /* p, p */
    double *c, *d;                    /* p, p: the first quadrature's weights */
} linear_chain;

/* Parameters drawn from a fixed generator seeded by seed; NULL if out of memory. */
linear_chain *linear_chain_new(size_t p, unsigned seed);
void linear_chain_free(linear_chain *lc);
/* The problem (n = 2 p + 2) and a starting state y0 (size n) with every block moving. */
bk_ode_problem linear_chain_problem(linear_chain *lc);
void linear_chain_start(const linear_chain *lc, double *y0);

#endif
