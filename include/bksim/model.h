/* The Burridge-Knopoff model: N blocks on a rigid surface in a rows x cols lattice (a chain
 * is one row), nearest neighbours joined by coupling springs, each block pulled by its own
 * driver spring.
 *
 *   m_i x_i'' = F_i(x, D(t)) + G_i(v) - s_i f_i
 *   F_i = k_i (D - x_i)          driver spring (tension_only: k_i max(0, D - x_i))
 *       + sum_j kc (x_j - x_i)   coupling to the neighbours j (left, right, up, down)
 *       + a_i                    a constant applied force (prestress, an edge pushed)
 *   G_i = -eta_i v_i             dashpot to the substrate (radiation damping)
 *       + sum_j etac (v_j - v_i) dashpots beside the coupling springs
 *
 * x_i is the displacement from the relaxed reference configuration (m), D the driver
 * displacement, f_i the friction force magnitude, s_i the slip direction.  Block i sits at
 * row i / cols, column i % cols.  Boundaries, per direction: free (edge blocks have one
 * neighbour that way), fixed (edge blocks also tied to a wall at 0), periodic (the last
 * block couples to the first; a direction one block long then has no spring). */
#ifndef BKSIM_MODEL_H
#define BKSIM_MODEL_H

#include <stddef.h>

#include "bksim/driver.h"
#include "bksim/friction.h"
#include "bksim/status.h"

typedef enum bk_boundary {
    BK_BOUNDARY_FREE = 0,
    BK_BOUNDARY_FIXED = 1,
    BK_BOUNDARY_PERIODIC = 2
} bk_boundary;

typedef enum bk_spring {
    BK_SPRING_LINEAR = 0,      /* pushes and pulls */
    BK_SPRING_TENSION_ONLY = 1 /* pulls only: zero force when the block is ahead of the driver */
} bk_spring;

typedef struct bk_block {
    double mass;             /* kg, > 0 */
    double driver_stiffness; /* N/m, >= 0 */
    double normal_force;     /* N, > 0; default mass * gravity */
    double x_init;           /* m, initial displacement; default 0 */
    double v_init;           /* m/s, initial velocity; default 0 */
    double damping;          /* N s/m, >= 0: dashpot to the substrate, force -damping * v */
    double applied_force;    /* N, signed: a constant tangential force (prestress); default 0 */
    const bk_friction_law *law;
    double friction_params[BK_FRICTION_MAX_PARAMS]; /* in law->params order */
    size_t state_offset;     /* first friction state of this block in the model's state array */
} bk_block;

/* Neighbour directions, in the order forces are summed: a chain uses the first two. */
enum { BK_LEFT = 0, BK_RIGHT = 1, BK_UP = 2, BK_DOWN = 3, BK_MAX_NEIGHBOURS = 4 };

typedef struct bk_model {
    size_t n_blocks;
    size_t rows, cols;          /* n_blocks = rows * cols, row-major; bk_model_create: 1 x n */
    bk_boundary boundary_cols;  /* at the first and last column: a chain's ends */
    bk_boundary boundary_rows;  /* at the first and last row */
    double coupling_stiffness; /* N/m, >= 0 */
    double coupling_damping;   /* N s/m, >= 0: dashpot in parallel with every coupling spring */
    double gravity;            /* m/s^2, used for default normal forces */
    bk_spring spring;
    bk_driver driver;
    bk_block *blocks;          /* n_blocks entries, owned */
    size_t n_friction_state;   /* sum of the blocks' law->n_state */
    /* The friction states at t = 0 (n_friction_state, owned), or NULL: each law's own
     * initial state from its parameters.  Set by a run started from another's end. */
    double *state_init;
} bk_model;

/* Allocate a model of n blocks, zeroed, a chain (1 x n, free ends); NULL on allocation
 * failure. */
bk_model *bk_model_create(size_t n_blocks);
void bk_model_free(bk_model *model);
/* Assign friction state offsets; call after the blocks' laws are set. */
void bk_model_finalize(bk_model *model);

/* Driver-spring force on block i at block position x_i and driver position D (N). */
double bk_model_driver_force(const bk_model *model, size_t i, double x_i, double driver_pos);
/* Coupling-spring force on block i for positions x (N). */
double bk_model_coupling_force(const bk_model *model, size_t i, const double *x);
/* Force on block i from its springs and its constant applied force: driver + coupling +
 * applied_force (N); bk_model_damping_force adds the dashpots. */
double bk_model_applied_force(const bk_model *model, size_t i, const double *x, double driver_pos);
/* Dashpot force on block i for velocities v (N): its own damping and the coupling dashpots
 * (a fixed wall stands still). */
double bk_model_damping_force(const bk_model *model, size_t i, const double *v);
/* Some block has damping or the coupling springs have dashpots: the motion depends on v. */
int bk_model_is_damped(const bk_model *model);
/* Potential energy (J): the elastic energy stored in all springs, and the constant applied
 * forces' potential -sum a_i x_i (so that the energy balance holds with them). */
double bk_model_elastic_energy(const bk_model *model, const double *x, double driver_pos);
/* Kinetic energy (J). */
double bk_model_kinetic_energy(const bk_model *model, const double *v);
/* Upper bound on the chain's highest natural angular frequency (rad/s), Gershgorin. */
double bk_model_max_angular_frequency(const bk_model *model);
/* The period of the fastest damped oscillation (s), bounded as bk_model_max_angular_frequency
 * does but with each block's own dashpot, 2 pi / sqrt(k_i / m_i - (eta_i / 2 m_i)^2)
 * (dashpots between blocks only damp further); INFINITY when no block oscillates (each
 * overdamped by its dashpot, or without mass).  Undamped: 2 pi / bk_model_max_angular_frequency. */
double bk_model_damped_period(const bk_model *model);
/* The time scale default step limits come from (s): bk_model_damped_period, or where no block
 * oscillates the shortest relaxation time of a friction state at the driver's speed;
 * INFINITY when neither exists. */
double bk_model_step_time_scale(const bk_model *model);
/* Directions with coupling partners: 2 on a chain (left, right), 4 on a lattice (or a row
 * between fixed walls above and below). */
size_t bk_model_directions(const bk_model *model);
/* Coupling partners of block i, by direction (BK_LEFT ..): a block index, -1 for none, or
 * -2 for a fixed wall at displacement 0; partners[d] for d >= bk_model_directions are -1.
 * With periodic ends two blocks long both partners that way are the other block. */
void bk_model_neighbours(const bk_model *model, size_t i, long partners[BK_MAX_NEIGHBOURS]);
/* Number of neighbours block i is coupled to (walls included), 0..4. */
int bk_model_coupling_count(const bk_model *model, size_t i);
/* Block i's own stiffness (N/m): its driver spring and its coupling springs, the others held
 * fixed; sqrt of it over the mass is the block's natural angular frequency. */
double bk_model_block_stiffness(const bk_model *model, size_t i);
/* The first block whose law has a state or a velocity-dependent sliding force, or n_blocks
 * when there is none: every law Coulomb-like, so between mode changes the chain is linear
 * with constant coefficients, dashpots included (what method = exact needs). */
size_t bk_model_first_non_affine_block(const bk_model *model);
/* bk_model_first_non_affine_block(model) == n_blocks */
int bk_model_is_affine(const bk_model *model);
/* Whether the dashpots of every stretch of blocks that can slip together are proportional
 * to its masses and springs, C = alpha M + beta K (beta = coupling_damping /
 * coupling_stiffness, and (damping_i - beta driver_stiffness_i) / mass_i the same alpha for
 * every block): then each stretch's modes are independent damped oscillators, the exact
 * stepper's fast case, and method = auto picks it for such Coulomb scenes.  1 without
 * dashpots; blocks with mass only. */
int bk_model_damping_proportional(const bk_model *model);

#endif
