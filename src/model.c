/* Forces and energies of a Burridge-Knopoff chain (equations in include/bksim/model.h). */
#include "bksim/model.h"

#include <math.h>
#include <stdlib.h>

bk_model *bk_model_create(size_t n_blocks)
{
    if (n_blocks == 0)
        return NULL;
    bk_model *model = calloc(1, sizeof *model);
    if (!model)
        return NULL;
    model->blocks = calloc(n_blocks, sizeof *model->blocks);
    if (!model->blocks) {
        free(model);
        return NULL;
    }
    model->n_blocks = n_blocks;
    return model;
}

void bk_model_free(bk_model *model)
{
    if (!model)
        return;
    free(model->blocks);
    bk_driver_free_history(&model->driver);
    free(model);
}

void bk_model_finalize(bk_model *model)
{
    size_t offset = 0;
    for (size_t i = 0; i < model->n_blocks; ++i) {
        model->blocks[i].state_offset = offset;
        offset += model->blocks[i].law ? model->blocks[i].law->n_state : 0;
    }
    model->n_friction_state = offset;
}

double bk_model_driver_force(const bk_model *model, size_t i, double x_i, double driver_pos)
{
    double extension = driver_pos - x_i;
    if (model->spring == BK_SPRING_TENSION_ONLY && extension < 0.0)
        return 0.0;
    return model->blocks[i].driver_stiffness * extension;
}

void bk_model_neighbours(const bk_model *model, size_t i, long *left, long *right)
{
    size_t n = model->n_blocks;
    long wall_or_none = model->boundary == BK_BOUNDARY_FIXED ? -2 : -1;
    *left = i > 0 ? (long)i - 1 : wall_or_none;
    *right = i + 1 < n ? (long)i + 1 : wall_or_none;
    if (model->boundary == BK_BOUNDARY_PERIODIC && n > 1) {
        if (i == 0)
            *left = (long)n - 1;
        if (i + 1 == n)
            *right = 0;
    }
}

int bk_model_coupling_count(const bk_model *model, size_t i)
{
    long left, right;
    bk_model_neighbours(model, i, &left, &right);
    return (left != -1) + (right != -1);
}

double bk_model_block_stiffness(const bk_model *model, size_t i)
{
    return model->blocks[i].driver_stiffness + bk_model_coupling_count(model, i) * model->coupling_stiffness;
}

double bk_model_coupling_force(const bk_model *model, size_t i, const double *x)
{
    double kc = model->coupling_stiffness;
    if (kc == 0.0)
        return 0.0;
    long left, right;
    bk_model_neighbours(model, i, &left, &right);
    double force = 0.0;
    if (left != -1)
        force += kc * ((left >= 0 ? x[left] : 0.0) - x[i]);
    if (right != -1)
        force += kc * ((right >= 0 ? x[right] : 0.0) - x[i]);
    return force;
}

double bk_model_applied_force(const bk_model *model, size_t i, const double *x, double driver_pos)
{
    return bk_model_driver_force(model, i, x[i], driver_pos) + bk_model_coupling_force(model, i, x);
}

double bk_model_damping_force(const bk_model *model, size_t i, const double *v)
{
    double force = -model->blocks[i].damping * v[i];
    double etac = model->coupling_damping;
    if (etac == 0.0)
        return force;
    long left, right;
    bk_model_neighbours(model, i, &left, &right);
    if (left != -1)
        force += etac * ((left >= 0 ? v[left] : 0.0) - v[i]);
    if (right != -1)
        force += etac * ((right >= 0 ? v[right] : 0.0) - v[i]);
    return force;
}

int bk_model_is_damped(const bk_model *model)
{
    /* Coupling dashpots exist where coupling springs do: between blocks, or to fixed walls. */
    if (model->coupling_damping > 0.0 && (model->n_blocks > 1 || model->boundary == BK_BOUNDARY_FIXED))
        return 1;
    for (size_t i = 0; i < model->n_blocks; ++i)
        if (model->blocks[i].damping > 0.0)
            return 1;
    return 0;
}

double bk_model_elastic_energy(const bk_model *model, const double *x, double driver_pos)
{
    size_t n = model->n_blocks;
    double kc = model->coupling_stiffness;
    double energy = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double extension = driver_pos - x[i];
        if (!(model->spring == BK_SPRING_TENSION_ONLY && extension < 0.0))
            energy += 0.5 * model->blocks[i].driver_stiffness * extension * extension;
    }
    if (kc == 0.0)
        return energy;
    /* Each spring once: the one to the right of every block, plus the left wall. */
    for (size_t i = 0; i < n; ++i) {
        long left, right;
        bk_model_neighbours(model, i, &left, &right);
        if (right >= 0) {
            double d = x[right] - x[i];
            energy += 0.5 * kc * d * d;
        } else if (right == -2) {
            energy += 0.5 * kc * x[i] * x[i];
        }
        if (left == -2)
            energy += 0.5 * kc * x[i] * x[i];
    }
    return energy;
}

double bk_model_kinetic_energy(const bk_model *model, const double *v)
{
    double energy = 0.0;
    for (size_t i = 0; i < model->n_blocks; ++i)
        energy += 0.5 * model->blocks[i].mass * v[i] * v[i];
    return energy;
}

double bk_model_max_angular_frequency(const bk_model *model)
{
    /* Gershgorin: |lambda| of M^-1 K is at most max_i (k_i + 2 * coupling_i * kc) / m_i. */
    double max_rate = 0.0;
    for (size_t i = 0; i < model->n_blocks; ++i) {
        const bk_block *b = &model->blocks[i];
        double row = b->driver_stiffness + 2.0 * bk_model_coupling_count(model, i) * model->coupling_stiffness;
        double rate = row / b->mass;
        if (rate > max_rate)
            max_rate = rate;
    }
    return sqrt(max_rate);
}

size_t bk_model_first_non_affine_block(const bk_model *model)
{
    for (size_t i = 0; i < model->n_blocks; ++i) {
        const bk_friction_law *law = model->blocks[i].law;
        if (law->n_state > 0 || !(law->flags & BK_FRICTION_CONSTANT_SLIDING))
            return i;
    }
    return model->n_blocks;
}

int bk_model_is_affine(const bk_model *model)
{
    return bk_model_first_non_affine_block(model) == model->n_blocks;
}
