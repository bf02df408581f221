/* Internal: the chain's state during a run and the compact ODE the integrator sees.
 *
 * Only slipping blocks carry dynamics.  Between two (re)starts the integrated vector is,
 * in chain order, per block: [xi, v] if slipping (xi = x - x_ref, the slip since the
 * restart, so the integrator's error scales with the slip, not the absolute position),
 * then the block's friction state if its law has any; and last two energy increments since
 * the restart: driver work and frictional dissipation.  Stuck blocks keep x = x_ref, v = 0.
 *
 * The full layout (full_layout set; only for a back-end that asks, IDA) keeps [xi, v] of
 * stuck blocks too, as rows xi' = v (differential) and 0 = -v (algebraic: the residual
 * diag(id) y' - f reads v), so the vector's size never changes.  It costs 2 unknowns per
 * stuck block, so the other back-ends keep the compact ODE: the DAE is IDA's choice. */
#ifndef BKSIM_SCENE_H
#define BKSIM_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/model.h"
#include "bksim/modes.h"

/* Root slots per block: 0 = breakaway (stuck) or stop (slipping), 1 = slip-rate minimum,
 * 2 = driver spring going slack/taut (tension-only springs only). */
enum { BK_ROOT_MAIN = 0, BK_ROOT_EXTREMUM = 1, BK_ROOT_SLACK = 2 };

typedef struct bk_scene {
    const bk_model *model;
    size_t n;                /* blocks */
    int8_t *mode;            /* bk_mode per block */
    double *x_ref;           /* m, positions at the last restart (stuck blocks: their position) */
    double *x;               /* m, current positions (unpacked) */
    double *v;               /* m/s, current velocities (unpacked) */
    double *state;           /* friction states, model->n_friction_state */
    double *normal;          /* N, per block */
    double *t_switch;        /* s, when each block last started slipping from rest */
    uint8_t *from_rest;      /* 1 when the current slip started at zero velocity at t_switch */
    uint8_t *taut;           /* tension-only springs: 1 while the spring pulls.  Held fixed
                                between restarts, like the slip direction, so the right-hand
                                side stays smooth and the slack root is located on a smooth
                                solution; the restart at that root flips it. */
    int detect_extrema;      /* use the slip-rate minimum roots */
    uint8_t *can_stick;      /* the block's law has a static threshold */
    uint8_t *extremum_armed; /* the slip-rate minimum root is live.  A minimum only follows
                                a deceleration, so the root is armed once s a is seen
                                clearly negative and disarmed at a slip start and after each
                                minimum: it never starts at or hovers around zero (a slip
                                that starts with zero acceleration, steady sliding). */

    /* Layout, rebuilt at every restart. */
    int full_layout;         /* stuck blocks stay in y (see above); set before the first restart */
    size_t *slot;            /* per block: index of xi in y, or SIZE_MAX when stuck (compact) */
    size_t *state_slot;      /* per block: index of its first friction state in y */
    size_t n_y;              /* length of y */
    size_t n_active;         /* slipping blocks */
    size_t half_bandwidth;   /* Jacobian half bandwidth of the layout */
    double t_ref;            /* s, time of the last restart */
    double work_ref;         /* J, driver work up to t_ref */
    double dissipation_ref;  /* J, dissipation up to t_ref */
    double stuck_taut_stiffness; /* N/m, sum of k_i over stuck blocks with a taut driver spring */
    double stuck_force_ref;      /* N, their driver-spring forces at t_ref */
    size_t *active;          /* the n_active slipping blocks, chain order */
    double *active_mass;     /* kg, their masses in the same order */
    double *differential_id; /* n_y: 1 for a differential component, 0 for an algebraic one */
    int affine;              /* the compact ODE is affine in y and t (see bk_ode_problem) */
    size_t *stateful;        /* blocks whose law carries state */
    size_t n_stateful;
    long *left, *right;      /* coupling partners (bk_model_neighbours) */

    /* Unpacked energies at the current time. */
    double work;             /* J */
    double dissipation;      /* J */

    size_t roots_per_block;  /* 2, or 3 with tension-only springs */
    int *root_direction;     /* n * roots_per_block */
} bk_scene;

int bk_scene_init(bk_scene *scene, const bk_model *model, int detect_extrema);
/* Block i is stuck in the current layout: a mode changes only at an event, which a restart
 * follows (a block that cannot stick only flips its slip direction). */
static inline int bk_scene_stuck(const bk_scene *scene, size_t i)
{
    return scene->mode[i] == BK_MODE_STICK;
}
void bk_scene_free(bk_scene *scene);

/* Rebuild the layout for the current modes at time t (x, v, state, work, dissipation hold
 * the state there) and write the integrator's starting vector into y (size n_y). */
void bk_scene_restart(bk_scene *scene, double t, double *y);
/* Per-component absolute tolerances for the current layout. */
void bk_scene_tolerances(const bk_scene *scene, double atol_x, double atol_v, double atol_state,
                         double atol_energy, double *atol);
/* Arm the slip-rate minimum roots of blocks now clearly decelerating (call at step ends;
 * a disarmed root reads as +1 and its direction is rising-only, so arming cannot fake a
 * crossing). */
void bk_scene_arm(bk_scene *scene, double t, const double *y);
/* Slip acceleration s a of slipping block i for the integrated vector y (m/s^2). */
double bk_scene_slip_acceleration(const bk_scene *scene, size_t i, double t, const double *y);
/* Fill x, v, state, work, dissipation from the integrated vector y at time t. */
void bk_scene_unpack(bk_scene *scene, double t, const double *y);

/* The ODE right-hand side and root functions for the current layout (bk_ode_problem); in
 * the full layout f of the semi-explicit DAE, a stuck block's velocity row being -v. */
int bk_scene_rhs(double t, const double *y, double *ydot, void *scene);
/* The exact Jacobian of bk_scene_rhs (see bk_ode_problem.jacobian); friction-law
 * derivatives by central differences. */
int bk_scene_jacobian(double t, const double *y, void *scene,
                      void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix);
int bk_scene_roots(double t, const double *y, double *g, void *scene);
/* The IMEX split of bk_scene_rhs (bk_ode_problem.rhs_split): friction implicit, the rest
 * explicit; f_explicit + f_implicit = bk_scene_rhs. */
int bk_scene_rhs_split(double t, const double *y, double *f_explicit, double *f_implicit, void *scene);
/* d f_implicit / dy. */
int bk_scene_jacobian_implicit(double t, const double *y, void *scene,
                               void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix);

/* Applied (spring) force on block i with the unpacked positions at driver position D. */
double bk_scene_applied_force(const bk_scene *scene, size_t i, double driver_pos);
/* Static threshold of block i (N) with its current friction state; +inf-free. */
double bk_scene_static_threshold(const bk_scene *scene, size_t i);
/* Sliding force magnitude of block i at slip rate s*v (N). */
double bk_scene_sliding_force(const bk_scene *scene, size_t i, double slip_rate);
/* Shear force the interface carries at block i (N, positive when it resists +x motion):
 * the applied force when stuck, s * sliding force when slipping. */
double bk_scene_friction(const bk_scene *scene, size_t i, double driver_pos);

#endif
