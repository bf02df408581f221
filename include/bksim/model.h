/* The Burridge-Knopoff chain: N blocks on a rigid surface, neighbours joined by coupling
 * springs, each block pulled by its own driver spring.
 *
 *   m_i x_i'' = F_i(x, D(t)) + G_i(v) - s_i f_i
 *   F_i = k_i (D - x_i)          driver spring (tension_only: k_i max(0, D - x_i))
 *       + kc (x_{i+1} - x_i) + kc (x_{i-1} - x_i)   coupling, per the boundary
 *   G_i = -eta_i v_i             dashpot to the substrate (radiation damping)
 *       + etac (v_{i+1} - v_i) + etac (v_{i-1} - v_i)   dashpots beside the coupling springs
 *
 * x_i is the displacement from the relaxed reference configuration (m), D the driver
 * displacement, f_i the friction force magnitude, s_i the slip direction.  Boundaries:
 * free (end blocks have one neighbour), fixed (end blocks also tied to a wall at 0),
 * periodic (block N-1 couples to block 0). */
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
    const bk_friction_law *law;
    double friction_params[BK_FRICTION_MAX_PARAMS]; /* in law->params order */
    size_t state_offset;     /* first friction state of this block in the model's state array */
} bk_block;

typedef struct bk_model {
    size_t n_blocks;
    bk_boundary boundary;
    double coupling_stiffness; /* N/m, >= 0 */
    double coupling_damping;   /* N s/m, >= 0: dashpot in parallel with every coupling spring */
    double gravity;            /* m/s^2, used for default normal forces */
    bk_spring spring;
    bk_driver driver;
    bk_block *blocks;          /* n_blocks entries, owned */
    size_t n_friction_state;   /* sum of the blocks' law->n_state */
} bk_model;

/* Allocate a model of n blocks, zeroed; NULL on allocation failure. */
bk_model *bk_model_create(size_t n_blocks);
void bk_model_free(bk_model *model);
/* Assign friction state offsets; call after the blocks' laws are set. */
void bk_model_finalize(bk_model *model);

/* Driver-spring force on block i at block position x_i and driver position D (N). */
double bk_model_driver_force(const bk_model *model, size_t i, double x_i, double driver_pos);
/* Coupling-spring force on block i for positions x (N). */
double bk_model_coupling_force(const bk_model *model, size_t i, const double *x);
/* Spring force on block i: driver + coupling (N); bk_model_damping_force adds the dashpots. */
double bk_model_applied_force(const bk_model *model, size_t i, const double *x, double driver_pos);
/* Dashpot force on block i for velocities v (N): its own damping and the coupling dashpots
 * (a fixed wall stands still). */
double bk_model_damping_force(const bk_model *model, size_t i, const double *v);
/* Some block has damping or the coupling springs have dashpots: the motion depends on v. */
int bk_model_is_damped(const bk_model *model);
/* Elastic energy stored in all springs (J). */
double bk_model_elastic_energy(const bk_model *model, const double *x, double driver_pos);
/* Kinetic energy (J). */
double bk_model_kinetic_energy(const bk_model *model, const double *v);
/* Upper bound on the chain's highest natural angular frequency (rad/s), Gershgorin. */
double bk_model_max_angular_frequency(const bk_model *model);
/* Coupling partners of block i: a block index, -1 for none, or -2 for a fixed wall at
 * displacement 0.  With periodic ends and two blocks both partners are the other block. */
void bk_model_neighbours(const bk_model *model, size_t i, long *left, long *right);
/* Number of neighbours block i is coupled to (walls included), 0..2. */
int bk_model_coupling_count(const bk_model *model, size_t i);
/* Block i's own stiffness (N/m): its driver spring and its coupling springs, the others held
 * fixed; sqrt of it over the mass is the block's natural angular frequency. */
double bk_model_block_stiffness(const bk_model *model, size_t i);
/* The first block whose law has a state or a velocity-dependent sliding force, or n_blocks
 * when there is none: every law Coulomb-like, so between mode changes the chain is linear
 * with constant coefficients (what method = exact needs). */
size_t bk_model_first_non_affine_block(const bk_model *model);
/* bk_model_first_non_affine_block(model) == n_blocks */
int bk_model_is_affine(const bk_model *model);

#endif
