/* The chain's state during a run (scene.h): per-block arrays, forces and thresholds on the
 * unpacked positions, friction states at rest, and the driver springs' energy.  The islands'
 * ODEs are in island.c. */
#include "scene.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int bk_scene_init(bk_scene *scene, const bk_model *model, int detect_extrema)
{
    memset(scene, 0, sizeof *scene);
    size_t n = model->n_blocks;
    scene->model = model;
    scene->n = n;
    scene->detect_extrema = detect_extrema;
    scene->roots_per_block = model->spring == BK_SPRING_TENSION_ONLY ? 3 : 2;
    scene->mode = calloc(n, sizeof *scene->mode);
    scene->x_ref = calloc(n, sizeof *scene->x_ref);
    scene->x = calloc(n, sizeof *scene->x);
    scene->v = calloc(n, sizeof *scene->v);
    scene->state = calloc(model->n_friction_state + 1, sizeof *scene->state);
    scene->state_time = calloc(n, sizeof *scene->state_time);
    scene->normal = calloc(n, sizeof *scene->normal);
    scene->t_switch = calloc(n, sizeof *scene->t_switch);
    scene->from_rest = calloc(n, sizeof *scene->from_rest);
    scene->taut = calloc(n, sizeof *scene->taut);
    scene->can_stick = calloc(n, sizeof *scene->can_stick);
    scene->extremum_armed = calloc(n, sizeof *scene->extremum_armed);
    scene->slot = malloc(n * sizeof *scene->slot);
    scene->state_slot = malloc(n * sizeof *scene->state_slot);
    scene->island_of = malloc(n * sizeof *scene->island_of);
    scene->n_directions = bk_model_directions(model);
    scene->partner = malloc(n * scene->n_directions * sizeof *scene->partner);
    if (!scene->mode || !scene->x_ref || !scene->x || !scene->v || !scene->state ||
        !scene->state_time || !scene->normal || !scene->t_switch || !scene->from_rest ||
        !scene->taut || !scene->can_stick || !scene->extremum_armed || !scene->slot ||
        !scene->state_slot || !scene->island_of || !scene->partner) {
        bk_scene_free(scene);
        return -1;
    }
    /* Stateless constant-force laws and a constant-velocity driver make every frozen-mode
     * segment affine, dashpots included (the exact stepper; the dashpots' dissipation, its
     * one quadratic rate, is declared to it as such). */
    scene->damped = bk_model_is_damped(model);
    scene->affine = bk_model_is_affine(model);
    scene->n_energy = scene->damped ? 3 : 2;
    for (size_t i = 0; i < n; ++i) {
        const bk_block *b = &model->blocks[i];
        scene->normal[i] = b->normal_force;
        scene->can_stick[i] = (b->law->flags & BK_FRICTION_STATIC_THRESHOLD) != 0;
        scene->x[i] = scene->x_ref[i] = b->x_init;
        scene->v[i] = b->v_init;
        scene->slot[i] = scene->state_slot[i] = BK_NO_SLOT;
        scene->island_of[i] = BK_NO_ISLAND;
        scene->taut[i] = 1;
        long partners[BK_MAX_NEIGHBOURS];
        bk_model_neighbours(model, i, partners);
        memcpy(&scene->partner[i * scene->n_directions], partners, scene->n_directions * sizeof *partners);
        if (b->law->n_state > 0)
            b->law->state_init(b->friction_params, &scene->state[b->state_offset]);
        if (b->law->n_state > scene->max_block_state)
            scene->max_block_state = b->law->n_state;
    }
    if (model->state_init)
        memcpy(scene->state, model->state_init, model->n_friction_state * sizeof *scene->state);
    return 0;
}

void bk_scene_free(bk_scene *scene)
{
    free(scene->mode);
    free(scene->x_ref);
    free(scene->x);
    free(scene->v);
    free(scene->state);
    free(scene->state_time);
    free(scene->normal);
    free(scene->t_switch);
    free(scene->from_rest);
    free(scene->taut);
    free(scene->can_stick);
    free(scene->extremum_armed);
    free(scene->slot);
    free(scene->state_slot);
    free(scene->island_of);
    free(scene->partner);
    free(scene->track_of);
    free(scene->tracks);
    free(scene->ghost_x);
    free(scene->ghost_v);
    memset(scene, 0, sizeof *scene);
}

static const double *stored_state(const bk_scene *scene, size_t i)
{
    const bk_block *b = &scene->model->blocks[i];
    return b->law->n_state ? &scene->state[b->state_offset] : NULL;
}

double bk_scene_applied_force(const bk_scene *scene, size_t i, double driver_pos)
{
    double force = bk_model_applied_force(scene->model, i, scene->x, driver_pos);
    return scene->damped ? force + bk_model_damping_force(scene->model, i, scene->v) : force;
}

double bk_scene_static_threshold(const bk_scene *scene, size_t i)
{
    const bk_block *b = &scene->model->blocks[i];
    return b->law->static_threshold(b->friction_params, scene->normal[i], stored_state(scene, i));
}

double bk_scene_sliding_force(const bk_scene *scene, size_t i, double slip_rate)
{
    const bk_block *b = &scene->model->blocks[i];
    return b->law->sliding_force(b->friction_params, scene->normal[i], slip_rate,
                                 stored_state(scene, i));
}

double bk_scene_friction(const bk_scene *scene, size_t i, double driver_pos)
{
    int dir = bk_mode_direction((bk_mode)scene->mode[i]);
    if (dir == 0)
        return bk_scene_applied_force(scene, i, driver_pos);
    return dir * bk_scene_sliding_force(scene, i, dir * scene->v[i]);
}

size_t bk_scene_state_at_rest(const bk_scene *scene, size_t i, double t, double *out)
{
    const bk_block *b = &scene->model->blocks[i];
    size_t ns = b->law->n_state;
    if (ns == 0)
        return 0;
    memcpy(out, &scene->state[b->state_offset], ns * sizeof *out);
    double dt = t - scene->state_time[i];
    if (dt > 0.0)
        b->law->state_advance(b->friction_params, 0.0, dt, out);
    return ns;
}

void bk_scene_age(bk_scene *scene, size_t i, double t)
{
    const bk_block *b = &scene->model->blocks[i];
    if (b->law->n_state > 0 && t > scene->state_time[i])
        b->law->state_advance(b->friction_params, 0.0, t - scene->state_time[i],
                              &scene->state[b->state_offset]);
    scene->state_time[i] = t;
}

double bk_scene_driver_spring_energy(const bk_scene *scene, size_t i, double driver_pos)
{
    const bk_model *model = scene->model;
    double extension = driver_pos - scene->x[i];
    if (model->spring == BK_SPRING_TENSION_ONLY && extension < 0.0)
        return 0.0;
    return 0.5 * model->blocks[i].driver_stiffness * extension * extension;
}
