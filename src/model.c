/* Forces and energies of a Burridge-Knopoff chain (equations in include/bksim/model.h). */
#include "bksim/model.h"

#include <float.h>
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
    model->rows = 1;
    model->cols = n_blocks;
    return model;
}

void bk_model_free(bk_model *model)
{
    if (!model)
        return;
    free(model->blocks);
    free(model->state_init);
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

size_t bk_model_directions(const bk_model *model)
{
    /* A single row has partners up and down only between fixed walls. */
    return model->rows > 1 || model->boundary_rows == BK_BOUNDARY_FIXED ? 4 : 2;
}

/* The partners before and after position p along a direction of length len. */
static void along(bk_boundary boundary, size_t p, size_t len, long stride, long i, long *before, long *after)
{
    long wall_or_none = boundary == BK_BOUNDARY_FIXED ? -2 : -1;
    *before = p > 0 ? i - stride : wall_or_none;
    *after = p + 1 < len ? i + stride : wall_or_none;
    if (boundary == BK_BOUNDARY_PERIODIC && len > 1) {
        if (p == 0)
            *before = i + (long)(len - 1) * stride;
        if (p + 1 == len)
            *after = i - (long)(len - 1) * stride;
    }
}

void bk_model_neighbours(const bk_model *model, size_t i, long partners[BK_MAX_NEIGHBOURS])
{
    size_t row = i / model->cols, col = i % model->cols;
    along(model->boundary_cols, col, model->cols, 1, (long)i, &partners[BK_LEFT], &partners[BK_RIGHT]);
    partners[BK_UP] = partners[BK_DOWN] = -1;
    if (bk_model_directions(model) > 2)
        along(model->boundary_rows, row, model->rows, (long)model->cols, (long)i, &partners[BK_UP],
              &partners[BK_DOWN]);
}

int bk_model_coupling_count(const bk_model *model, size_t i)
{
    long partners[BK_MAX_NEIGHBOURS];
    bk_model_neighbours(model, i, partners);
    int count = 0;
    for (size_t d = 0; d < BK_MAX_NEIGHBOURS; ++d)
        count += partners[d] != -1;
    return count;
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
    long partners[BK_MAX_NEIGHBOURS];
    bk_model_neighbours(model, i, partners);
    double force = 0.0;
    for (size_t d = 0; d < BK_MAX_NEIGHBOURS; ++d)
        if (partners[d] != -1)
            force += kc * ((partners[d] >= 0 ? x[partners[d]] : 0.0) - x[i]);
    return force;
}

double bk_model_applied_force(const bk_model *model, size_t i, const double *x, double driver_pos)
{
    return bk_model_driver_force(model, i, x[i], driver_pos) + bk_model_coupling_force(model, i, x) +
           model->blocks[i].applied_force;
}

double bk_model_damping_force(const bk_model *model, size_t i, const double *v)
{
    double force = -model->blocks[i].damping * v[i];
    double etac = model->coupling_damping;
    if (etac == 0.0)
        return force;
    long partners[BK_MAX_NEIGHBOURS];
    bk_model_neighbours(model, i, partners);
    for (size_t d = 0; d < BK_MAX_NEIGHBOURS; ++d)
        if (partners[d] != -1)
            force += etac * ((partners[d] >= 0 ? v[partners[d]] : 0.0) - v[i]);
    return force;
}

int bk_model_is_damped(const bk_model *model)
{
    /* Coupling dashpots exist where coupling springs do: between blocks, or to fixed walls. */
    if (model->coupling_damping > 0.0)
        for (size_t i = 0; i < model->n_blocks; ++i)
            if (bk_model_coupling_count(model, i) > 0)
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
        energy -= model->blocks[i].applied_force * x[i];
        double extension = driver_pos - x[i];
        if (!(model->spring == BK_SPRING_TENSION_ONLY && extension < 0.0))
            energy += 0.5 * model->blocks[i].driver_stiffness * extension * extension;
    }
    if (kc == 0.0)
        return energy;
    /* Each spring once: the ones right of and below every block, plus walls left and above. */
    for (size_t i = 0; i < n; ++i) {
        long partners[BK_MAX_NEIGHBOURS];
        bk_model_neighbours(model, i, partners);
        static const size_t order[] = {BK_RIGHT, BK_LEFT, BK_DOWN, BK_UP};
        for (size_t k = 0; k < BK_MAX_NEIGHBOURS; ++k) {
            long j = partners[order[k]];
            int after = order[k] == BK_RIGHT || order[k] == BK_DOWN;
            if (after && j >= 0) {
                double gap = x[j] - x[i];
                energy += 0.5 * kc * gap * gap;
            } else if (j == -2) {
                energy += 0.5 * kc * x[i] * x[i];
            }
        }
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
        if (!(b->mass > 0.0))
            continue; /* without mass, no oscillator */
        double row = b->driver_stiffness + 2.0 * bk_model_coupling_count(model, i) * model->coupling_stiffness;
        double rate = row / b->mass;
        if (rate > max_rate)
            max_rate = rate;
    }
    return sqrt(max_rate);
}

/* A step limit exists so that a root cannot hide inside one step: a stop, or a slip-rate
 * extremum, inside an oscillation.  A block that cannot oscillate hides none, and the only
 * scale left to it is its friction's: a state relaxing over Dc / v. */
double bk_model_damped_period(const bk_model *model)
{
    double max_rate = 0.0;
    for (size_t i = 0; i < model->n_blocks; ++i) {
        const bk_block *b = &model->blocks[i];
        if (!(b->mass > 0.0))
            continue;
        double row = b->driver_stiffness + 2.0 * bk_model_coupling_count(model, i) * model->coupling_stiffness;
        double decay = b->damping / (2.0 * b->mass);
        double rate = row / b->mass - decay * decay;
        if (rate > max_rate)
            max_rate = rate;
    }
    return max_rate > 0.0 ? 2.0 * 3.14159265358979323846 / sqrt(max_rate) : INFINITY;
}

double bk_model_step_time_scale(const bk_model *model)
{
    double period = bk_model_damped_period(model);
    if (isfinite(period))
        return period;
    double speed = fabs(model->driver.velocity);
    double shortest = INFINITY;
    for (size_t i = 0; i < model->n_blocks && speed > 0.0; ++i) {
        const bk_block *b = &model->blocks[i];
        if (b->law && b->law->relaxation_time)
            shortest = fmin(shortest, b->law->relaxation_time(b->friction_params, speed));
    }
    return shortest;
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

int bk_model_damping_proportional(const bk_model *model)
{
    size_t n = model->n_blocks;
    double kc = model->coupling_stiffness, etac = model->coupling_damping;
    if (n <= 1 || (kc == 0.0 && etac == 0.0))
        return 1; /* every slipping stretch is one block */
    if (etac > 0.0 && !(kc > 0.0))
        return 0; /* blocks tied by dashpots alone */
    double beta = etac > 0.0 ? etac / kc : 0.0;
    /* a slack driver spring drops out of K, not its share beta k_p of C */
    if (beta > 0.0 && model->spring == BK_SPRING_TENSION_ONLY)
        for (size_t i = 0; i < n; ++i)
            if (model->blocks[i].driver_stiffness != 0.0)
                return 0;
    const bk_block *b0 = &model->blocks[0];
    double alpha = (b0->damping - beta * b0->driver_stiffness) / b0->mass;
    double scale0 = (b0->damping + beta * b0->driver_stiffness) / b0->mass;
    for (size_t i = 1; i < n; ++i) {
        const bk_block *b = &model->blocks[i];
        double a = (b->damping - beta * b->driver_stiffness) / b->mass;
        double scale = fmax(scale0, (b->damping + beta * b->driver_stiffness) / b->mass);
        if (!(fabs(a - alpha) <= 64.0 * DBL_EPSILON * scale))
            return 0;
    }
    return 1;
}
