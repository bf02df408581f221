/* Internal: the chain's (or lattice's) state during a run, and the islands the integrator
 * sees.
 *
 * Stuck blocks split the slipping ones into independent groups.  An island is a connected
 * component of the slipping blocks and their neighbours, joined only through slipping
 * blocks: on a chain a run of blocks (cyclic on a ring), slipping stretches that only one
 * stuck block separates, together with the stuck blocks next to them.  A stuck block's breakaway then
 * depends on one island only, and a stuck block next to no slipping block ("quiet") on
 * nothing that moves: its failure time follows in closed form from the driver's motion and
 * needs no integrator at all.  Each island is integrated on its own, so the work of a step
 * or an event is proportional to the island, not to the chain.
 *
 * An island's integrated vector is, in the island's block order, per block: [xi, v] if slipping (xi =
 * x - x_ref, the slip since the island's restart, so the integrator's error scales with the
 * slip, not the absolute position), then the block's friction state if its law has any; and
 * last the energy increments since the restart: the driver work on its slipping blocks, their
 * frictional dissipation and, with dashpots, the dashpots' dissipation (scene->n_energy).
 * Stuck blocks keep x = x_ref, v = 0.
 *
 * The full layout (full_layout set; only for a back-end that asks, IDA) keeps [xi, v] of an
 * island's stuck blocks too, as rows xi' = v (differential) and 0 = -v (algebraic: the
 * residual diag(id) y' - f reads v), so the vector's size never changes between restarts
 * of one island.  It costs 2 unknowns per stuck block, so the other back-ends keep the
 * compact ODE: the DAE is IDA's choice. */
#ifndef BKSIM_SCENE_H
#define BKSIM_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "bksim/model.h"
#include "bksim/modes.h"
#include "bksim/solver.h"

/* Root slots per block: 0 = breakaway (stuck) or stop (slipping), 1 = slip-rate minimum,
 * 2 = driver spring going slack/taut (tension-only springs only). */
enum { BK_ROOT_MAIN = 0, BK_ROOT_EXTREMUM = 1, BK_ROOT_SLACK = 2 };

#define BK_NO_SLOT SIZE_MAX
#define BK_NO_ISLAND SIZE_MAX

typedef struct bk_scene {
    const bk_model *model;
    size_t n;                /* blocks */
    int8_t *mode;            /* bk_mode per block */
    double *x_ref;           /* m, positions at the island's last restart (stuck blocks: their position) */
    double *x;               /* m, current positions (unpacked) */
    double *v;               /* m/s, current velocities (unpacked) */
    double *state;           /* friction states, model->n_friction_state; a quiet block's
                                refer to state_time */
    double *state_time;      /* s, per block: when its stored friction state was current */
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
    int full_layout;         /* islands keep their stuck blocks in y (see above) */
    int affine;              /* every law Coulomb-like: islands' ODEs are affine in y and t (but
                                for the dashpots' dissipation, quadratic in v) */
    int damped;              /* some dashpot (bk_model_is_damped) */
    double balance_time;     /* s: blocks without mass return to their force balance at this
                                time constant when the integration drifts off it (island.c) */
    size_t n_energy;         /* energy increments at the end of an island's y: driver work, friction
                                dissipation and, when damped, dashpot dissipation */
    size_t *slot;            /* per block: index of xi in its island's y, or BK_NO_SLOT */
    size_t *state_slot;      /* per block: index of its first friction state in its island's y */
    size_t *island_of;       /* per block: its island, or BK_NO_ISLAND (quiet) */
    long *partner;           /* coupling partners (bk_model_neighbours), n_directions per block */
    size_t n_directions;     /* bk_model_directions: 2 on a chain, 4 on a lattice */
    size_t roots_per_block;  /* 2, or 3 with tension-only springs */
    size_t max_block_state;  /* friction states of the most stateful block */
    double slip_threshold;   /* m/s: the event catalog's slip rate for laws without a stuck
                                state (0: none; then their roots stay silent) */
    uint8_t *above;          /* per block of such a law: |v| above slip_threshold (NULL: none) */
    /* Local time stepping (run_segments.c): the chain is cut into segments, islands each with
     * its own integrator and time, coupled through their edge blocks.  A partner in another
     * segment is a ghost: its position and velocity at the time of an evaluation come from
     * the track its segment publishes (below), and go into ghost_x, ghost_v. */
    int segmented;
    size_t *track_of;        /* per block: its track, or BK_NO_TRACK (not next to another segment) */
    struct bk_track *tracks;
    double *ghost_x, *ghost_v; /* m, m/s: per block, as last evaluated for a neighbouring segment */
} bk_scene;

#define BK_NO_TRACK SIZE_MAX

/* What a segment publishes about one of its edge blocks after each step: the integrator's
 * own polynomial (its predictor, which is also its dense output over the last step) for the
 * block's slip and velocity, about the step's end t_n, and how far ahead it can be trusted. */
typedef struct bk_track {
    double t_n;              /* s */
    double x0;               /* m: the block's position at its segment's restart (x = x0 + slip) */
    double limit;            /* s: extrapolation is trusted up to here */
    double safety;           /* lookahead factor, halved after each coupling error measured over 1 */
    int order;
    double slip[BK_PREDICTOR_MAX_ORDER + 1];     /* m / s^k: Taylor coefficients about t_n */
    double velocity[BK_PREDICTOR_MAX_ORDER + 1]; /* m/s / s^k */
} bk_track;

static inline double bk_track_horner(const double *coef, int order, double s)
{
    double value = coef[order];
    for (int k = order - 1; k >= 0; --k)
        value = value * s + coef[k];
    return value;
}

/* Position and velocity of a track's block at t. */
static inline void bk_track_eval(const bk_track *track, double t, double *x, double *v)
{
    double s = t - track->t_n;
    *x = track->x0 + bk_track_horner(track->slip, track->order, s);
    *v = bk_track_horner(track->velocity, track->order, s);
}

int bk_scene_init(bk_scene *scene, const bk_model *model, int detect_extrema);
void bk_scene_free(bk_scene *scene);
/* Block i is stuck in the current layout: a mode changes only at an event, which a restart
 * follows (a block that cannot stick only flips its slip direction). */
static inline int bk_scene_stuck(const bk_scene *scene, size_t i)
{
    return scene->mode[i] == BK_MODE_STICK;
}

/* Block i's coupling partners, scene->n_directions of them (bk_model_neighbours). */
static inline const long *bk_scene_partners(const bk_scene *scene, size_t i)
{
    return &scene->partner[i * scene->n_directions];
}
/* Neighbours block i is coupled to, walls included (bk_model_coupling_count). */
static inline int bk_scene_coupling_count(const bk_scene *scene, size_t i)
{
    const long *partner = bk_scene_partners(scene, i);
    int count = 0;
    for (size_t d = 0; d < scene->n_directions; ++d)
        count += partner[d] != -1;
    return count;
}

/* Applied force on block i, springs and dashpots, with the unpacked positions and velocities at
 * driver position D. */
double bk_scene_applied_force(const bk_scene *scene, size_t i, double driver_pos);
/* Static threshold of block i (N) with its stored friction state. */
double bk_scene_static_threshold(const bk_scene *scene, size_t i);
/* Sliding force magnitude of block i at slip rate s*v (N). */
double bk_scene_sliding_force(const bk_scene *scene, size_t i, double slip_rate);
/* Shear force the interface carries at block i (N, positive when it resists +x motion):
 * the applied force when stuck, s * sliding force when slipping. */
double bk_scene_friction(const bk_scene *scene, size_t i, double driver_pos);
/* The friction state of block i at rest, aged from state_time to t (at most
 * BK_FRICTION_MAX_STATE values into out; stored state untouched).  A block without state: 0. */
size_t bk_scene_state_at_rest(const bk_scene *scene, size_t i, double t, double *out);
/* Age a resting block's stored state to t (state_time = t). */
void bk_scene_age(bk_scene *scene, size_t i, double t);
/* Energy in block i's driver spring at driver position D (J): what the driver's work on a
 * stuck block adds up to. */
double bk_scene_driver_spring_energy(const bk_scene *scene, size_t i, double driver_pos);

/* Energies the run integrates rather than reads off the state (J). */
typedef struct bk_energy {
    double work;     /* done by the driver */
    double friction; /* dissipated by friction */
    double damping;  /* dissipated by the dashpots */
} bk_energy;

static inline void bk_energy_add(bk_energy *sum, const bk_energy *more)
{
    sum->work += more->work;
    sum->friction += more->friction;
    sum->damping += more->damping;
}

/* An island: len blocks, listed in the partition's order (run_partition.c: a chain's run
 * from its first block, a lattice's blocks row by row), so that coupled blocks sit close in y. */
typedef struct bk_island {
    bk_scene *scene;
    size_t id;               /* index in the run's island table */
    size_t *blocks;          /* its len blocks */
    size_t len;
    /* Layout, rebuilt at every restart. */
    size_t n_y;              /* length of y */
    size_t n_active;         /* slipping blocks */
    size_t half_bandwidth;   /* Jacobian half bandwidth of the layout */
    double t_ref;            /* s, time of the last restart */
    size_t driver_segment;   /* the driver's segment at the restart: its line is the driver until the
                                next restart, which every breakpoint is */
    size_t *active;          /* the n_active slipping blocks, chain order from start */
    double *active_mass;     /* kg, their masses in the same order */
    size_t *stateful;        /* blocks whose law carries state */
    size_t n_stateful;
    double *differential_id; /* n_y: 1 for a differential component, 0 for an algebraic one */
    int *root_direction;     /* roots_per_block * len */
    int affine;              /* the compact ODE is affine in y and t (see bk_ode_problem) */
    size_t n_massless;       /* active blocks without mass (quasi-dynamic; island.c) */
    size_t capacity;         /* blocks the arrays above have room for */
    /* A segment's (scene->segmented) partners in other segments, and its own blocks next to
     * them, found at every restart. */
    size_t *ghosts, n_ghosts;
    size_t *edges, n_edges;
    size_t ghost_capacity;   /* room in each of the two */
} bk_island;

static inline size_t bk_island_block(const bk_island *island, size_t k)
{
    return island->blocks[k];
}
static inline size_t bk_island_n_roots(const bk_island *island)
{
    return island->scene->roots_per_block * island->len;
}
/* The length of y an island over these len blocks gets for their current modes. */
size_t bk_island_y_length(const bk_scene *scene, const size_t *blocks, size_t len);
/* Longest y an island of len blocks can need. */
size_t bk_island_max_y(const bk_scene *scene, size_t len);

/* Room for an island of len blocks (arrays grow, never shrink, and the block list does not
 * survive a growth); -1 when out of memory. */
int bk_island_reserve(bk_island *island, size_t len);
void bk_island_free(bk_island *island);
/* Rebuild the layout for the current modes at time t (x, v and state of the island's blocks
 * hold the state there) and write the integrator's starting vector into y (size n_y). */
void bk_island_restart(bk_island *island, double t, double *y);
/* Per-component absolute tolerances for the current layout. */
void bk_island_tolerances(const bk_island *island, double atol_x, double atol_v, double atol_state,
                          double atol_energy, double *atol);
/* Arm the slip-rate minimum roots of blocks now clearly decelerating (call at step ends;
 * a disarmed root reads as +1 and its direction is rising-only, so arming cannot fake a
 * crossing). */
void bk_island_arm(bk_island *island, double t, const double *y);
/* Slip acceleration s a of slipping block i for the integrated vector y (m/s^2). */
double bk_island_slip_acceleration(const bk_island *island, size_t i, double t, const double *y);
/* Fill x, v and state of the island's blocks from y at time t; *increments (may be NULL)
 * receives the energy increments since the restart. */
void bk_island_unpack(bk_island *island, double t, const double *y, bk_energy *increments);

/* The ODE right-hand side and root functions of an island (bk_ode_problem, user = island);
 * in the full layout f of the semi-explicit DAE, a stuck block's velocity row being -v.
 * Root k belongs to block bk_island_block(island, k / roots_per_block). */
int bk_island_rhs(double t, const double *y, double *ydot, void *island);
/* The exact Jacobian of bk_island_rhs (see bk_ode_problem.jacobian); friction-law
 * derivatives by central differences. */
int bk_island_jacobian(double t, const double *y, void *island,
                       void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix);
int bk_island_roots(double t, const double *y, double *g, void *island);
/* The IMEX split of bk_island_rhs (bk_ode_problem.rhs_split): friction implicit, the rest
 * explicit; f_explicit + f_implicit = bk_island_rhs. */
int bk_island_rhs_split(double t, const double *y, double *f_explicit, double *f_implicit, void *island);
/* d f_implicit / dy. */
int bk_island_jacobian_implicit(double t, const double *y, void *island,
                                void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix);

#endif
