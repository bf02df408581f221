/* An island's compact ODE, or IDA's full-layout DAE (layouts in scene.h): right-hand side,
 * root functions, Jacobian, and packing between the chain's arrays and the island's vector.
 * Everything here costs time in proportion to the island, never to the chain: blocks
 * outside the island are stuck, and only their positions enter (as fixed ends), or under
 * local time stepping belong to a neighbouring segment, and enter as ghosts, their positions
 * and velocities read off that segment's published tracks (scene.h, run_segments.c).
 *
 * Root functions, per block of the island (all clearly non-zero right after the block
 * switched, so a just-handled root cannot fire again after a restart):
 *   stuck:    g = F_s - |F|                    falls through 0 at breakaway
 *   slipping: g = s v / (t - t_switch)         falls through 0 at the stop; at t_switch it
 *             (s v when the slip did not        equals its limit s a > 0 instead of 0
 *              start from rest)
 *             g = s a                          rises through 0 at a slip-rate minimum, where
 *                                              a stop hidden inside one step shows as s v < 0
 *   tension-only spring: g = D - x             the spring's kink (slack/taut) */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "capacity.h"
#include "scene.h"

size_t bk_island_max_y(const bk_scene *scene, size_t len)
{
    return len * (2 + scene->max_block_state) + scene->n_energy;
}

size_t bk_island_y_length(const bk_scene *scene, const size_t *blocks, size_t len)
{
    size_t n_y = scene->n_energy;
    for (size_t k = 0; k < len; ++k) {
        size_t i = blocks[k];
        if (!bk_scene_stuck(scene, i) || scene->full_layout)
            n_y += 2;
        n_y += scene->model->blocks[i].law->n_state;
    }
    return n_y;
}

int bk_island_reserve(bk_island *island, size_t len)
{
    size_t room = len * island->scene->n_directions;
    if (island->scene->segmented && room > island->ghost_capacity) {
        size_t *ghosts = realloc(island->ghosts, room * sizeof *ghosts);
        if (!ghosts)
            return -1;
        island->ghosts = ghosts;
        size_t *edges = realloc(island->edges, room * sizeof *edges);
        if (!edges)
            return -1;
        island->edges = edges;
        island->ghost_capacity = room;
    }
    if (bk_capacity_fits(len, island->capacity))
        return 0;
    size_t max_y = bk_island_max_y(island->scene, len);
    size_t R = island->scene->roots_per_block;
    /* One block for every layout array: an island's step reads them together. */
    size_t bytes = len * (3 * sizeof(size_t) + sizeof(double)) + max_y * sizeof(double) +
                   R * len * sizeof(int);
    char *block = malloc(bytes);
    if (!block)
        return -1;
    free(island->blocks);
    island->blocks = (size_t *)(void *)block;
    island->active = island->blocks + len;
    island->stateful = island->active + len;
    island->active_mass = (double *)(void *)(island->stateful + len);
    island->differential_id = island->active_mass + len;
    island->root_direction = (int *)(void *)(island->differential_id + max_y);
    island->capacity = len;
    return 0;
}

void bk_island_free(bk_island *island)
{
    free(island->ghosts);
    free(island->edges);
    island->ghosts = island->edges = NULL;
    island->n_ghosts = island->n_edges = island->ghost_capacity = 0;
    free(island->blocks); /* the block holding every layout array */
    island->blocks = island->active = island->stateful = NULL;
    island->active_mass = island->differential_id = NULL;
    island->root_direction = NULL;
    island->capacity = 0;
}

/* Position of block j given the island's vector: blocks integrated by this island from y,
 * every other block stuck, so fixed at x_ref, or (segmented) a ghost, as refresh_ghosts last
 * evaluated it. */
static inline double position(const bk_island *island, const double *y, long j)
{
    if (j < 0)
        return 0.0; /* a fixed wall */
    const bk_scene *scene = island->scene;
    size_t s = scene->slot[j];
    if (scene->island_of[j] != island->id)
        return scene->segmented ? scene->ghost_x[j] : scene->x_ref[j];
    if (s == BK_NO_SLOT)
        return scene->x_ref[j];
    return scene->x_ref[j] + y[s];
}

/* The ghosts' positions and velocities at t, before anything here reads them.  Every entry
 * point that evaluates forces calls it: a neighbouring segment may have stepped since. */
static void refresh_ghosts(const bk_island *island, double t)
{
    bk_scene *scene = island->scene;
    for (size_t g = 0; g < island->n_ghosts; ++g) {
        size_t j = island->ghosts[g];
        bk_track_eval(&scene->tracks[scene->track_of[j]], t, &scene->ghost_x[j], &scene->ghost_v[j]);
    }
}

/* A segment's ghosts and edge blocks (scene.h), from the partition as it stands (room
 * reserved by bk_island_reserve). */
static void find_ghosts(bk_island *island)
{
    bk_scene *scene = island->scene;
    island->n_ghosts = island->n_edges = 0;
    for (size_t k = 0; k < island->len; ++k) {
        size_t i = bk_island_block(island, k);
        const long *partner = bk_scene_partners(scene, i);
        int edge = 0;
        for (size_t d = 0; d < scene->n_directions; ++d) {
            if (partner[d] < 0 || scene->island_of[partner[d]] == island->id)
                continue;
            edge = 1;
            size_t j = (size_t)partner[d];
            int seen = 0; /* a small ring's two sides can be one block */
            for (size_t g = 0; g < island->n_ghosts && !seen; ++g)
                seen = island->ghosts[g] == j;
            if (!seen)
                island->ghosts[island->n_ghosts++] = j;
        }
        if (edge)
            island->edges[island->n_edges++] = i;
    }
}

/* Driver-spring force with the spring's taut/slack state frozen since the restart. */
/* Velocity of block j: this island's blocks from y, a ghost as last evaluated, any other
 * block (stuck) and a wall 0. */
static inline double velocity(const bk_island *island, const double *y, long j)
{
    if (j < 0)
        return 0.0;
    const bk_scene *scene = island->scene;
    size_t s = scene->slot[j];
    if (scene->island_of[j] != island->id)
        return scene->segmented ? scene->ghost_v[j] : 0.0;
    if (s == BK_NO_SLOT)
        return 0.0;
    return y[s + 1];
}

static inline double driver_force(const bk_scene *scene, size_t i, double x_i, double driver_pos)
{
    if (scene->model->spring == BK_SPRING_TENSION_ONLY && !scene->taut[i])
        return 0.0;
    return scene->model->blocks[i].driver_stiffness * (driver_pos - x_i);
}

static inline double coupling_force(const bk_island *island, const double *y, size_t i, double x_i)
{
    const bk_scene *scene = island->scene;
    double kc = scene->model->coupling_stiffness;
    if (kc == 0.0)
        return 0.0;
    double force = 0.0;
    const long *partner = bk_scene_partners(scene, i);
    for (size_t d = 0; d < scene->n_directions; ++d)
        if (partner[d] != -1)
            force += kc * (position(island, y, partner[d]) - x_i);
    return force;
}

/* The force on block i that does not depend on velocity: its driver spring, its coupling
 * springs and its constant applied force (bk_model_applied_force on the island's vector). */
static inline double load_force(const bk_island *island, const double *y, size_t i, double x_i, double driver_pos)
{
    return driver_force(island->scene, i, x_i, driver_pos) + coupling_force(island, y, i, x_i) +
           island->scene->model->blocks[i].applied_force;
}

/* Dashpot force on block i (bk_model_damping_force on the island's vector); nothing is looked
 * up without dashpots, as the right-hand side and roots run for every scene. */
static inline double damping_force(const bk_island *island, const double *y, size_t i)
{
    const bk_scene *scene = island->scene;
    if (!scene->damped)
        return 0.0;
    const bk_model *model = scene->model;
    double v_i = velocity(island, y, (long)i);
    double force = -model->blocks[i].damping * v_i;
    double etac = model->coupling_damping;
    if (etac > 0.0) {
        const long *partner = bk_scene_partners(scene, i);
        for (size_t d = 0; d < scene->n_directions; ++d)
            if (partner[d] != -1)
                force += etac * (velocity(island, y, partner[d]) - v_i);
    }
    return force;
}

static inline const double *block_state(const bk_island *island, const double *y, size_t i)
{
    const bk_scene *scene = island->scene;
    const bk_block *b = &scene->model->blocks[i];
    if (b->law->n_state == 0)
        return NULL;
    return y ? &y[scene->state_slot[i]] : &scene->state[b->state_offset];
}

/* The Jacobian's half bandwidth: within a block and to its chain neighbours (`local`), and
 * between the integrated blocks coupled right or down (on a lattice, a row apart).  A
 * periodic seam, where the partner comes earlier in the island's order, is left out: the
 * band solver drops that corner, as an approximate Newton matrix may. */
static size_t half_bandwidth(const bk_island *island, size_t local)
{
    const bk_scene *scene = island->scene;
    size_t width = local;
    if (scene->n_directions <= 2)
        return width; /* chain neighbours are adjacent in the layout */
    for (size_t k = 0; k < island->len; ++k) {
        size_t i = island->blocks[k], s = scene->slot[i];
        if (s == BK_NO_SLOT)
            continue;
        long p = bk_scene_partners(scene, i)[BK_DOWN];
        if (p >= 0 && scene->island_of[p] == island->id && scene->slot[p] != BK_NO_SLOT && scene->slot[p] > s &&
            scene->slot[p] - s + 1 > width)
            width = scene->slot[p] - s + 1;
    }
    return width;
}

/* d(sliding force)/d(slip rate) and d/d(state) of block i (N s/m, N per state unit). */
static void friction_derivatives(const bk_scene *scene, size_t i, double slip_rate, const double *state,
                                 double *d_rate, double *d_state)
{
    const bk_block *b = &scene->model->blocks[i];
    const bk_friction_law *law = b->law;
    if (law->sliding_force_derivatives) {
        law->sliding_force_derivatives(b->friction_params, scene->normal[i], slip_rate, state, d_rate, d_state);
        return;
    }
    double h = 1e-6 * fmax(fabs(slip_rate), 1e-9);
    *d_rate = (law->sliding_force(b->friction_params, scene->normal[i], slip_rate + h, state) -
               law->sliding_force(b->friction_params, scene->normal[i], slip_rate - h, state)) /
              (2.0 * h);
    if (law->n_state == 0) {
        *d_state = 0.0;
        return;
    }
    double shifted[BK_FRICTION_MAX_STATE];
    double hs = 1e-6 * fmax(fabs(state[0]), 1e-12);
    shifted[0] = state[0] + hs;
    double up = law->sliding_force(b->friction_params, scene->normal[i], slip_rate, shifted);
    shifted[0] = state[0] - hs;
    double down = law->sliding_force(b->friction_params, scene->normal[i], slip_rate, shifted);
    *d_state = (up - down) / (2.0 * hs);
}

/* --- blocks without mass (quasi-dynamic) ------------------------------------------------
 * Such a block's slip rate is fixed by its force balance
 *     Phi(v) = A - eta v - F(v, theta) = 0,   A = driver spring + coupling springs,
 * (no dashpots between blocks: config_build.c refuses them), which falls strictly in v for a
 * law that never sticks (F odd and increasing in v, eta > 0).  The ODE back-ends integrate v
 * as QDYN does, by the balance's time derivative
 *     v' = (A' - dF/dtheta theta') / (eta + dF/dv),   A' = k (V_driver - v) + sum kc (v_j - v),
 * plus a pull back onto the balance (balance_acceleration), and every restart puts v on
 * the balance itself (balance_velocity), to rounding.  IDA keeps the balance
 * as the algebraic row it is (Phi in the velocity row, differential_id 0). */

/* The rate of change of the springs' force on block i (N/s). */
static double spring_load_rate(const bk_island *island, const double *y, size_t i)
{
    const bk_scene *scene = island->scene;
    const bk_model *model = scene->model;
    double driver_speed = bk_driver_segment_velocity(&model->driver, island->driver_segment);
    double v_i = velocity(island, y, (long)i);
    int taut = model->spring == BK_SPRING_LINEAR || scene->taut[i];
    double rate = taut ? model->blocks[i].driver_stiffness * (driver_speed - v_i) : 0.0;
    double kc = model->coupling_stiffness;
    if (kc != 0.0) {
        const long *partner = bk_scene_partners(scene, i);
        for (size_t d = 0; d < scene->n_directions; ++d)
            if (partner[d] != -1)
                rate += kc * (velocity(island, y, partner[d]) - v_i);
    }
    return rate;
}

/* The slip rate of block i (without mass) on its force balance, bracketed Newton to
 * rounding: Phi(0) = A and Phi(A / eta) = -F(A / eta) bracket the root. */
static double balance_velocity(const bk_island *island, double t, const double *y, size_t i, double guess)
{
    const bk_scene *scene = island->scene;
    const bk_block *b = &scene->model->blocks[i];
    const double *state = block_state(island, y, i);
    double driver_pos = bk_driver_segment_position(&scene->model->driver, island->driver_segment, t);
    double x_i = position(island, y, (long)i);
    double load = load_force(island, y, i, x_i, driver_pos);
    double eta = b->damping;
    double lo = fmin(0.0, load / eta), hi = fmax(0.0, load / eta);
    double v = guess > lo && guess < hi ? guess : 0.5 * (lo + hi);
    for (int iter = 0; iter < 200 && hi > lo; ++iter) {
        double d_rate, d_state;
        double phi = load - eta * v - b->law->sliding_force(b->friction_params, scene->normal[i], v, state);
        if (phi == 0.0)
            return v;
        if (phi > 0.0)
            lo = v;
        else
            hi = v;
        friction_derivatives(scene, i, v, state, &d_rate, &d_state);
        double next = v + phi / (eta + d_rate);
        if (!(next > lo && next < hi))
            next = 0.5 * (lo + hi);
        if (fabs(next - v) <= 2.0 * DBL_EPSILON * fabs(v) || next == lo || next == hi)
            return next;
        v = next;
    }
    return v;
}

/* v' of block i (without mass) from the balance's time derivative, given the balance's
 * residual Phi = A - eta v - F(v, theta) at y (the right-hand side has it already). */
static double balance_acceleration(const bk_island *island, const double *y, size_t i, double residual)
{
    const bk_scene *scene = island->scene;
    const bk_block *b = &scene->model->blocks[i];
    const double *state = block_state(island, y, i);
    double d_rate, d_state;
    double v_i = y[scene->slot[i] + 1];
    friction_derivatives(scene, i, v_i, state, &d_rate, &d_state);
    double state_change = 0.0;
    if (state) {
        double st_rate[BK_FRICTION_MAX_STATE];
        b->law->state_rate(b->friction_params, fabs(v_i), state, st_rate);
        state_change = d_state * st_rate[0];
    }
    /* d Phi / dt = -Phi / balance_time: zero on the balance, so the exact solution is the
     * balance's, while the integrator's drift off it (which the derivative alone keeps and
     * accumulates between restarts) decays instead. */
    return (spring_load_rate(island, y, i) - state_change + residual / scene->balance_time) /
           (b->damping + d_rate);
}

void bk_island_restart(bk_island *island, double t, double *y)
{
    bk_scene *scene = island->scene;
    const bk_model *model = scene->model;
    size_t next = 0, R = scene->roots_per_block;
    size_t max_state = 0;
    island->n_active = 0;
    island->n_stateful = 0;
    island->n_massless = 0;
    island->affine = scene->affine && !scene->full_layout;
    island->driver_segment = bk_driver_segment(&model->driver, t);
    double driver_pos = bk_driver_segment_position(&model->driver, island->driver_segment, t);
    double driver_speed = bk_driver_segment_velocity(&model->driver, island->driver_segment);
    for (size_t k = 0; k < island->len; ++k) {
        size_t i = bk_island_block(island, k);
        const bk_block *b = &model->blocks[i];
        scene->x_ref[i] = scene->x[i];
        scene->island_of[i] = island->id;
        int dir = bk_mode_direction((bk_mode)scene->mode[i]);
        double extension = driver_pos - scene->x[i];
        /* At the kink itself the spring is taut if the driver is pulling away. */
        scene->taut[i] = model->spring == BK_SPRING_LINEAR || extension > 0.0 ||
                         (extension == 0.0 &&
                          driver_speed - (dir != 0 ? scene->v[i] : 0.0) > 0.0);
        if (dir != 0) {
            scene->slot[i] = next;
            island->active_mass[island->n_active] = b->mass;
            island->active[island->n_active++] = i;
            y[next] = 0.0;
            y[next + 1] = scene->v[i];
            island->differential_id[next] = 1.0;
            /* Without mass, IDA keeps the force balance as an algebraic row. */
            island->differential_id[next + 1] = b->mass > 0.0 || !scene->full_layout ? 1.0 : 0.0;
            if (!(b->mass > 0.0))
                island->n_massless++;
            next += 2;
        } else {
            scene->v[i] = 0.0;
            scene->slot[i] = scene->full_layout ? next : BK_NO_SLOT;
            if (scene->full_layout) {
                /* Consistent as it stands: v = 0 satisfies the constraint, xi' = v = 0. */
                y[next] = y[next + 1] = 0.0;
                island->differential_id[next] = 1.0;
                island->differential_id[next + 1] = 0.0;
                next += 2;
            }
        }
        size_t ns = b->law->n_state;
        if (ns > 0) {
            /* A block that joins from rest carries the state it aged to. */
            if (dir == 0)
                bk_scene_age(scene, i, t);
            island->stateful[island->n_stateful++] = i;
            scene->state_slot[i] = next;
            memcpy(&y[next], &scene->state[b->state_offset], ns * sizeof *y);
            for (size_t j = 0; j < ns; ++j)
                island->differential_id[next + j] = 1.0;
            next += ns;
            if (ns > max_state)
                max_state = ns;
        }
        /* A threshold crossing is located either way: the integration runs on through it
         * (run_events.c), so the direction to look for next is not known at a restart. */
        island->root_direction[R * k + BK_ROOT_MAIN] = scene->can_stick[i] ? -1 : 0;
        island->root_direction[R * k + BK_ROOT_EXTREMUM] = dir != 0 && scene->can_stick[i] ? +1 : 0;
        if (R > 2)
            island->root_direction[R * k + BK_ROOT_SLACK] = 0;
    }
    /* Driver work on the slipping blocks, friction and dashpot dissipation since t. */
    for (size_t e = 0; e < scene->n_energy; ++e) {
        y[next + e] = 0.0;
        island->differential_id[next + e] = 1.0;
    }
    island->n_y = next + scene->n_energy;
    island->half_bandwidth = half_bandwidth(island, 3 + max_state);
    island->t_ref = t;
    if (scene->segmented) {
        find_ghosts(island);
        refresh_ghosts(island, t);
    }
    /* Blocks without mass start on their force balance (the whole layout is in place now:
     * the balance reads the neighbours' positions). */
    for (size_t k = 0; k < island->n_active && island->n_massless > 0; ++k) {
        size_t i = island->active[k], s = scene->slot[i];
        if (model->blocks[i].mass > 0.0)
            continue;
        y[s + 1] = balance_velocity(island, t, y, i, y[s + 1]);
        scene->v[i] = y[s + 1];
        if (y[s + 1] != 0.0)
            scene->mode[i] = (int8_t)(y[s + 1] > 0.0 ? BK_MODE_SLIP_POS : BK_MODE_SLIP_NEG);
    }
    for (size_t k = 0; k < island->n_active; ++k) {
        size_t i = island->active[k];
        if (scene->from_rest[i] && scene->t_switch[i] == t)
            scene->extremum_armed[i] = 0;
    }
    bk_island_arm(island, t, y);
}

void bk_island_tolerances(const bk_island *island, double atol_x, double atol_v, double atol_state,
                          double atol_energy, double *atol)
{
    const bk_scene *scene = island->scene;
    for (size_t k = 0; k < island->len; ++k) {
        size_t i = bk_island_block(island, k), s = scene->slot[i];
        if (s == BK_NO_SLOT)
            continue;
        atol[s] = atol_x;
        atol[s + 1] = atol_v;
    }
    for (size_t k = 0; k < island->n_stateful; ++k) {
        size_t i = island->stateful[k];
        for (size_t j = 0; j < scene->model->blocks[i].law->n_state; ++j)
            atol[scene->state_slot[i] + j] = atol_state;
    }
    for (size_t e = island->n_y - scene->n_energy; e < island->n_y; ++e)
        atol[e] = atol_energy;
}

void bk_island_unpack(bk_island *island, double t, const double *y, bk_energy *increments)
{
    bk_scene *scene = island->scene;
    const bk_model *model = scene->model;
    for (size_t k = 0; k < island->len; ++k) {
        size_t i = bk_island_block(island, k), s = scene->slot[i];
        if (s == BK_NO_SLOT) {
            scene->x[i] = scene->x_ref[i];
            scene->v[i] = 0.0;
        } else {
            /* In the full layout a stuck block too reports what the integrator holds. */
            scene->x[i] = scene->x_ref[i] + y[s];
            scene->v[i] = y[s + 1];
            /* A block that cannot stick reports the way it moves (its law is odd in v). */
            if (!scene->can_stick[i] && scene->v[i] != 0.0)
                scene->mode[i] = (int8_t)(scene->v[i] > 0.0 ? BK_MODE_SLIP_POS : BK_MODE_SLIP_NEG);
        }
    }
    for (size_t k = 0; k < island->n_stateful; ++k) {
        size_t i = island->stateful[k];
        const bk_block *b = &model->blocks[i];
        memcpy(&scene->state[b->state_offset], &y[scene->state_slot[i]],
               b->law->n_state * sizeof *y);
        scene->state_time[i] = t;
    }
    if (increments) {
        const double *energy = &y[island->n_y - scene->n_energy];
        increments->work = energy[0];
        increments->friction = energy[1];
        increments->damping = scene->damped ? energy[2] : 0.0;
    }
}

/* The right-hand side, whole (f_implicit NULL) or split: the friction and dashpot terms (the
 * velocity rows' (G - s F) / m, the state rates) into f_implicit and the rest into ydot.
 * The dashpots dissipate -sum v_i G_i over the island's blocks (each dashpot once: the pair
 * terms add up to etac (v_i - v_j)^2). */
static void rhs_parts(const bk_island *island, double t, const double *y, double *ydot,
                      double *f_implicit)
{
    const bk_scene *scene = island->scene;
    const bk_model *model = scene->model;
    double driver_pos = bk_driver_segment_position(&model->driver, island->driver_segment, t);
    double driver_force_sum = 0.0;
    double dissipation_rate = 0.0, damping_rate = 0.0;
    double *state_rates = f_implicit ? f_implicit : ydot;
    refresh_ghosts(island, t);
    if (f_implicit)
        memset(f_implicit, 0, island->n_y * sizeof *f_implicit);
    for (size_t k = 0; k < island->n_active; ++k) {
        size_t i = island->active[k], s = scene->slot[i];
        const bk_block *b = &model->blocks[i];
        double x_i = scene->x_ref[i] + y[s], v_i = y[s + 1];
        double dir = (double)scene->mode[i];
        double spring = driver_force(scene, i, x_i, driver_pos);
        double applied = spring + coupling_force(island, y, i, x_i) + b->applied_force;
        double dashpots = damping_force(island, y, i);
        double friction = b->law->sliding_force(b->friction_params, scene->normal[i], dir * v_i,
                                                block_state(island, y, i));
        ydot[s] = v_i;
        if (!(b->mass > 0.0)) {
            /* IDA: the balance itself; the ODE back-ends: its time derivative, stiff. */
            double residual = applied + dashpots - dir * friction;
            double row = scene->full_layout ? residual : balance_acceleration(island, y, i, residual);
            if (f_implicit) {
                ydot[s + 1] = 0.0;
                f_implicit[s + 1] = row;
            } else {
                ydot[s + 1] = row;
            }
        } else if (f_implicit) {
            ydot[s + 1] = applied / b->mass;
            f_implicit[s + 1] = (dashpots - dir * friction) / b->mass;
        } else {
            ydot[s + 1] = (applied + dashpots - dir * friction) / b->mass;
        }
        driver_force_sum += spring;
        dissipation_rate += dir * friction * v_i;
        damping_rate -= v_i * dashpots;
    }
    if (scene->full_layout)
        for (size_t k = 0; k < island->len; ++k) {
            size_t i = bk_island_block(island, k);
            if (bk_scene_stuck(scene, i)) {
                size_t s = scene->slot[i];
                ydot[s] = y[s + 1];       /* xi' = v */
                ydot[s + 1] = -y[s + 1]; /* 0 = -v, algebraic */
                if (scene->damped)
                    damping_rate -= y[s + 1] * damping_force(island, y, i);
            }
        }
    for (size_t k = 0; k < island->n_stateful; ++k) {
        size_t i = island->stateful[k];
        const bk_block *b = &model->blocks[i];
        /* A stuck block's state ages at rest.  In the full layout its v is 0 by the
         * constraint anyway, and |v| has no derivative there for the Jacobian. */
        double speed = bk_scene_stuck(scene, i) ? 0.0 : fabs(y[scene->slot[i] + 1]);
        b->law->state_rate(b->friction_params, speed, &y[scene->state_slot[i]],
                           &state_rates[scene->state_slot[i]]);
        if (f_implicit)
            for (size_t j = 0; j < b->law->n_state; ++j)
                ydot[scene->state_slot[i] + j] = 0.0;
    }
    double *energy_rates = &ydot[island->n_y - scene->n_energy];
    energy_rates[0] = bk_driver_segment_velocity(&model->driver, island->driver_segment) * driver_force_sum;
    energy_rates[1] = dissipation_rate;
    if (scene->damped)
        energy_rates[2] = damping_rate;
}

int bk_island_rhs(double t, const double *y, double *ydot, void *user)
{
    rhs_parts(user, t, y, ydot, NULL);
    return 0;
}

int bk_island_rhs_split(double t, const double *y, double *f_explicit, double *f_implicit, void *user)
{
    rhs_parts(user, t, y, f_explicit, f_implicit);
    return 0;
}

/* `value` at (row, slot + offset) of each partner of block i this island integrates: the
 * coupling's entries, to a partner's position (offset 0) or velocity (1). */
static void put_partners(const bk_island *island, size_t i, size_t row, size_t offset, double value,
                         void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix)
{
    const bk_scene *scene = island->scene;
    const long *partner = bk_scene_partners(scene, i);
    for (size_t d = 0; d < scene->n_directions; ++d)
        if (partner[d] >= 0 && scene->slot[partner[d]] != BK_NO_SLOT && scene->island_of[partner[d]] == island->id)
            put(matrix, row, scene->slot[partner[d]] + offset, value);
}

/* The dashpots' part for block i (integrated at slot s): d accel / d v of it and of its
 * partners here, and the dissipation rate's d / d v_i = -2 G_i (see rhs_parts). */
static void damping_jacobian(const bk_island *island, const double *y, size_t i, size_t s, int with_energy,
                             void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix)
{
    const bk_scene *scene = island->scene;
    const bk_model *model = scene->model;
    double etac = model->coupling_damping, m = model->blocks[i].mass > 0.0 ? model->blocks[i].mass : 1.0;
    if (!bk_scene_stuck(scene, i)) {
        put(matrix, s + 1, s + 1, -(model->blocks[i].damping + etac * bk_scene_coupling_count(scene, i)) / m);
        if (etac > 0.0)
            put_partners(island, i, s + 1, 1, etac / m, put, matrix);
    }
    if (with_energy)
        put(matrix, island->n_y - 1, s + 1, -2.0 * damping_force(island, y, i));
}

/* The Jacobian of the whole right-hand side, or (friction_only) of its friction and dashpot
 * part. */
static void jacobian_parts(const bk_island *island, const double *y, int friction_only,
                           void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix)
{
    const bk_scene *scene = island->scene;
    const bk_model *model = scene->model;
    double kc = model->coupling_stiffness;
    double speed = bk_driver_segment_velocity(&model->driver, island->driver_segment);
    size_t work_row = island->n_y - scene->n_energy, dissipation_row = work_row + 1;
    for (size_t k = 0; k < island->n_active; ++k) {
        size_t i = island->active[k], s = scene->slot[i];
        const bk_block *b = &model->blocks[i];
        /* A block without mass has its balance as the row (IDA only: the ODE layout of such
         * an island takes difference quotients, see run_islands.c), i.e. m = 1. */
        double dir = (double)scene->mode[i], v_i = y[s + 1], m = b->mass > 0.0 ? b->mass : 1.0;
        double spring = model->spring == BK_SPRING_TENSION_ONLY && !scene->taut[i] ? 0.0 : b->driver_stiffness;
        if (!friction_only) {
            put(matrix, s, s + 1, 1.0); /* xi' = v */
            /* Springs: the block's own stiffness, and its partners integrated here. */
            put(matrix, s + 1, s, -(spring + kc * bk_scene_coupling_count(scene, i)) / m);
            if (kc > 0.0)
                put_partners(island, i, s + 1, 0, kc / m, put, matrix);
        }
        /* Friction: -dir F(dir v, state) / m. */
        const double *state = block_state(island, y, i);
        double d_rate, d_state;
        friction_derivatives(scene, i, dir * v_i, state, &d_rate, &d_state);
        put(matrix, s + 1, s + 1, -d_rate / m);
        if (state)
            put(matrix, s + 1, scene->state_slot[i], -dir * d_state / m);
        if (scene->damped)
            damping_jacobian(island, y, i, s, !friction_only, put, matrix);
        if (friction_only)
            continue;
        /* Energy rates: driver power V k (D - x), friction power dir F v. */
        double force = b->law->sliding_force(b->friction_params, scene->normal[i], dir * v_i, state);
        put(matrix, work_row, s, -speed * spring);
        put(matrix, dissipation_row, s + 1, dir * force + v_i * d_rate);
        if (state)
            put(matrix, dissipation_row, scene->state_slot[i], dir * v_i * d_state);
    }
    if (scene->full_layout && !friction_only)
        for (size_t k = 0; k < island->len; ++k) {
            size_t i = bk_island_block(island, k);
            if (bk_scene_stuck(scene, i)) {
                size_t s = scene->slot[i];
                put(matrix, s, s + 1, 1.0);
                put(matrix, s + 1, s + 1, -1.0);
                if (scene->damped)
                    damping_jacobian(island, y, i, s, 1, put, matrix);
            }
        }
    /* State equations: d(rate)/d(state) and, while slipping, d(rate)/dv. */
    for (size_t k = 0; k < island->n_stateful; ++k) {
        size_t i = island->stateful[k], q = scene->state_slot[i], s = scene->slot[i];
        const bk_block *b = &model->blocks[i];
        int slipping = !bk_scene_stuck(scene, i);
        double v_i = slipping ? y[s + 1] : 0.0, spd = fabs(v_i);
        double st[BK_FRICTION_MAX_STATE], up[BK_FRICTION_MAX_STATE], down[BK_FRICTION_MAX_STATE];
        double hs = 1e-6 * fmax(fabs(y[q]), 1e-12);
        st[0] = y[q] + hs;
        b->law->state_rate(b->friction_params, spd, st, up);
        st[0] = y[q] - hs;
        b->law->state_rate(b->friction_params, spd, st, down);
        put(matrix, q, q, (up[0] - down[0]) / (2.0 * hs));
        if (slipping) {
            double hv = 1e-6 * fmax(spd, 1e-9);
            b->law->state_rate(b->friction_params, spd + hv, &y[q], up);
            b->law->state_rate(b->friction_params, fmax(spd - hv, 0.0), &y[q], down);
            double d_speed = (up[0] - down[0]) / (spd + hv - fmax(spd - hv, 0.0));
            put(matrix, q, s + 1, v_i >= 0.0 ? d_speed : -d_speed);
        }
    }
}

int bk_island_jacobian(double t, const double *y, void *user,
                       void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix)
{
    refresh_ghosts(user, t); /* the dashpots' dissipation reads ghosts' velocities */
    jacobian_parts(user, y, 0, put, matrix);
    return 0;
}

int bk_island_jacobian_implicit(double t, const double *y, void *user,
                                void (*put)(void *matrix, size_t row, size_t col, double value), void *matrix)
{
    refresh_ghosts(user, t);
    jacobian_parts(user, y, 1, put, matrix);
    return 0;
}

int bk_island_roots(double t, const double *y, double *g, void *user)
{
    const bk_island *island = user;
    const bk_scene *scene = island->scene;
    const bk_model *model = scene->model;
    size_t R = scene->roots_per_block;
    double driver_pos = bk_driver_segment_position(&model->driver, island->driver_segment, t);
    refresh_ghosts(island, t);
    for (size_t k = 0; k < island->len; ++k) {
        size_t i = bk_island_block(island, k);
        const bk_block *b = &model->blocks[i];
        double *gi = &g[R * k];
        double x_i = position(island, y, (long)i);
        double applied = load_force(island, y, i, x_i, driver_pos) + damping_force(island, y, i);
        const double *state = block_state(island, y, i);
        size_t s = scene->slot[i];
        if (!scene->can_stick[i]) {
            /* Smooth through v = 0: only the catalog's threshold to locate, if any. */
            gi[BK_ROOT_MAIN] = scene->slip_threshold > 0.0 ? fabs(y[s + 1]) - scene->slip_threshold : 1.0;
            gi[BK_ROOT_EXTREMUM] = 1.0;
        } else if (bk_scene_stuck(scene, i)) {
            gi[BK_ROOT_MAIN] = b->law->static_threshold(b->friction_params, scene->normal[i], state) -
                               fabs(applied);
            gi[BK_ROOT_EXTREMUM] = 1.0;
        } else {
            double dir = (double)scene->mode[i];
            double v_i = y[s + 1];
            double friction = b->law->sliding_force(b->friction_params, scene->normal[i], dir * v_i, state);
            double slip_accel = dir * (applied - dir * friction) / b->mass;
            double since = t - scene->t_switch[i];
            if (!scene->from_rest[i])
                gi[BK_ROOT_MAIN] = dir * v_i;
            else
                gi[BK_ROOT_MAIN] = since > 0.0 ? dir * v_i / since : slip_accel;
            gi[BK_ROOT_EXTREMUM] = scene->detect_extrema && scene->extremum_armed[i] ? slip_accel : 1.0;
        }
        if (R > 2)
            gi[BK_ROOT_SLACK] = driver_pos - x_i;
    }
    return 0;
}

double bk_island_slip_acceleration(const bk_island *island, size_t i, double t, const double *y)
{
    const bk_scene *scene = island->scene;
    const bk_block *b = &scene->model->blocks[i];
    size_t s = scene->slot[i];
    double driver_pos = bk_driver_segment_position(&scene->model->driver, island->driver_segment, t);
    double x_i = scene->x_ref[i] + y[s], v_i = y[s + 1];
    double dir = (double)scene->mode[i];
    refresh_ghosts(island, t);
    double applied = load_force(island, y, i, x_i, driver_pos) + damping_force(island, y, i);
    double friction = b->law->sliding_force(b->friction_params, scene->normal[i], dir * v_i,
                                            block_state(island, y, i));
    if (!(b->mass > 0.0))
        return dir * balance_acceleration(island, y, i, applied - dir * friction);
    return dir * (applied - dir * friction) / b->mass;
}

void bk_island_arm(bk_island *island, double t, const double *y)
{
    bk_scene *scene = island->scene;
    for (size_t k = 0; k < island->n_active; ++k) {
        size_t i = island->active[k];
        if (scene->extremum_armed[i] || !scene->can_stick[i])
            continue;
        const bk_block *b = &scene->model->blocks[i];
        double threshold = b->law->static_threshold(b->friction_params, scene->normal[i],
                                                    block_state(island, y, i));
        /* Clearly negative: well beyond the rounding of (force - friction) / m. */
        if (bk_island_slip_acceleration(island, i, t, y) < -1e-9 * threshold / b->mass)
            scene->extremum_armed[i] = 1;
    }
}
