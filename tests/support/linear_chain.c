#include "linear_chain.h"

#include <stdlib.h>

/* A small linear congruential generator: the same chain on every platform. */
static double uniform01(unsigned *state)
{
    *state = *state * 1664525u + 1013904223u;
    return (double)(*state >> 8) / 16777216.0;
}

linear_chain *linear_chain_new(size_t p, unsigned seed)
{
    linear_chain *lc = calloc(1, sizeof *lc);
    double *all = lc ? malloc(8 * p * sizeof *all) : NULL;
    if (!all) {
        free(lc);
        return NULL;
    }
    lc->p = p;
    lc->mass = all;
    lc->ground = all + p;
    lc->coupling = all + 2 * p;
    lc->force = all + 3 * p;
    lc->force_rate = all + 4 * p;
    lc->c = all + 5 * p;
    lc->d = all + 6 * p;
    unsigned s = seed;
    for (size_t i = 0; i < p; ++i) {
        lc->mass[i] = 0.5 + uniform01(&s);
        lc->ground[i] = 1e3 * (0.5 + uniform01(&s));
        lc->coupling[i] = 4e3 * (0.5 + uniform01(&s)); /* the last one is unused */
        lc->force[i] = uniform01(&s) - 0.5;
        lc->force_rate[i] = 0.1 * (uniform01(&s) - 0.5);
        lc->c[i] = uniform01(&s) - 0.5;
        lc->d[i] = uniform01(&s) - 0.5;
    }
    return lc;
}

void linear_chain_free(linear_chain *lc)
{
    if (lc)
        free(lc->mass);
    free(lc);
}

static int chain_rhs(double t, const double *y, double *ydot, void *user)
{
    const linear_chain *lc = user;
    size_t p = lc->p;
    double q0 = 1.0 + 0.5 * t, q1 = 0.0;
    for (size_t i = 0; i < p; ++i) {
        double x = y[2 * i], v = y[2 * i + 1];
        double f = -lc->ground[i] * x + lc->force[i] + lc->force_rate[i] * t;
        if (i > 0)
            f -= lc->coupling[i - 1] * (x - y[2 * i - 2]);
        if (i + 1 < p)
            f -= lc->coupling[i] * (x - y[2 * i + 2]);
        ydot[2 * i] = v;
        ydot[2 * i + 1] = f / lc->mass[i];
        q0 += lc->c[i] * x + lc->d[i] * v;
        q1 += v;
    }
    ydot[2 * p] = q0;
    ydot[2 * p + 1] = q1;
    return 0;
}

bk_ode_problem linear_chain_problem(linear_chain *lc)
{
    return (bk_ode_problem){.user = lc, .rhs = chain_rhs, .n_pairs = lc->p, .pair_mass = lc->mass,
                            .affine = 1, .half_bandwidth = 2};
}

void linear_chain_start(const linear_chain *lc, double *y0)
{
    unsigned s = 7u;
    for (size_t i = 0; i < lc->p; ++i) {
        y0[2 * i] = 1e-3 * (uniform01(&s) - 0.5) + 0.25;
        y0[2 * i + 1] = 1e-2 * (uniform01(&s) - 0.5);
    }
    y0[2 * lc->p] = 0.5;
    y0[2 * lc->p + 1] = -0.25;
}
