/* Test support: the exact piecewise-analytic motion of one block under Coulomb friction,
 * pulled at constant speed V > 0 from rest with the driver at the block (NOTES.md, last
 * section).  Independent of src/: a second derivation to test the integrator against.
 *
 * Phases: stuck (x fixed); slipping forward with a taut spring, harmonic about the
 * kinetic equilibrium e = f_k / k (e = D - x, the spring extension); slipping with a slack
 * tension-only spring, uniform deceleration f_k / m. */
#ifndef EXACT_SINGLE_H
#define EXACT_SINGLE_H

#include <stddef.h>

typedef struct exact_params {
    double mass, stiffness, normal, mu_s, mu_d, velocity;
    int tension_only;
} exact_params;

enum { EXACT_STUCK, EXACT_HARMONIC, EXACT_SLACK };

typedef struct exact_phase {
    int kind;
    double t0;       /* s, start */
    double x0, v0;   /* m, m/s at t0 */
    double e0;       /* m, spring extension D - x at t0 */
} exact_phase;

typedef struct exact_event {
    double t;   /* s */
    int from;   /* bk_mode values: 0 stick, 1 slip+ */
    int to;
    double x;   /* m */
    double force; /* N, spring force */
} exact_event;

typedef struct exact_solution {
    exact_params p;
    exact_phase *phases;
    size_t n_phases;
    exact_event *events;
    size_t n_events;
} exact_solution;

/* Solve on [0, t_end]; returns 0, or -1 if the motion leaves the cases derived here. */
int exact_solve(const exact_params *p, double t_end, exact_solution *out);
void exact_free(exact_solution *s);
/* Position (m) and velocity (m/s) at time t. */
void exact_state(const exact_solution *s, double t, double *x, double *v);

#endif
