/* When a quiet block breaks away.  A stuck block whose neighbours are stuck too is loaded by
 * its driver alone: its applied force is affine in the driver's position until a neighbour
 * moves (which rebuilds the partition around it and asks again), so the time its force
 * reaches the static threshold is known in closed form; for a law whose threshold ages at
 * rest, the first zero of the margin is bracketed and located by Brent. */
#include <math.h>

#include "run_ctx.h"

/* Samples of a stateful block's threshold margin per doubling of the look-ahead. */
#define AGING_SCAN_START (1.0 / 64.0)

/* The force on quiet block i at driver position D (its neighbours stuck, so fixed). */
static double quiet_force(const run_ctx *ctx, size_t i, double driver_pos)
{
    return bk_model_applied_force(ctx->model, i, ctx->scene.x, driver_pos);
}

/* Time block i breaks away with a constant threshold, from the applied force's affine
 * dependence on the driver position; +inf if never. */
static double coulomb_failure(const run_ctx *ctx, size_t i, double t, double threshold)
{
    const bk_model *model = ctx->model;
    const bk_scene *scene = &ctx->scene;
    double k = model->blocks[i].driver_stiffness;
    double velocity = bk_driver_velocity(&model->driver, t);
    if (k == 0.0 || velocity == 0.0)
        return INFINITY;
    /* Everything but the driver spring holds still while the neighbours do. */
    double held = bk_model_coupling_force(model, i, scene->x) + model->blocks[i].applied_force;
    /* The driver spring force rises with D when the driver advances, falls when it retreats;
     * a tension-only spring can only pull, so a retreating driver never breaks it away
     * unless the rest alone does. */
    double target_force = velocity > 0.0 ? threshold - held : -threshold - held;
    if (velocity < 0.0 && model->spring == BK_SPRING_TENSION_ONLY && target_force < 0.0)
        return INFINITY;
    double target_position = scene->x[i] + target_force / k;
    double here = bk_driver_position(&model->driver, t);
    if ((target_position - here) * velocity <= 0.0)
        return t;
    /* Within the driver's segment only: its breakpoint restarts everything and asks again. */
    double t_fail = bk_driver_time_at(&model->driver, t, target_position);
    return t_fail < ctx->t_breakpoint ? t_fail : INFINITY;
}

typedef struct aging_margin {
    const run_ctx *ctx;
    size_t block;
} aging_margin;

/* Threshold minus |applied force| of a resting block at time t. */
static double margin_at(double t, void *user)
{
    const aging_margin *m = user;
    const run_ctx *ctx = m->ctx;
    const bk_block *b = &ctx->model->blocks[m->block];
    double state[BK_FRICTION_MAX_STATE];
    bk_scene_state_at_rest(&ctx->scene, m->block, t, state);
    double threshold = b->law->static_threshold(b->friction_params, ctx->scene.normal[m->block], state);
    return threshold - fabs(quiet_force(ctx, m->block, bk_driver_position(&ctx->model->driver, t)));
}

/* The failure time of a resting block whose threshold ages (state at rest): the first zero
 * of the margin after t.  The margin is sampled at look-aheads doubling from a fraction of
 * the time the driver needs to load the spring by the threshold, then the crossing is
 * located by Brent.  Aging laws strengthen the contact concavely in time while the driver
 * loads it linearly, so the margin has one falling zero and sampling cannot step over it. */
static double aging_failure(run_ctx *ctx, size_t i, double t)
{
    aging_margin m = {ctx, i};
    double g0 = margin_at(t, &m);
    if (!(g0 > 0.0))
        return t;
    const bk_block *b = &ctx->model->blocks[i];
    double speed = fabs(bk_driver_velocity(&ctx->model->driver, t));
    if (b->driver_stiffness == 0.0 || speed == 0.0)
        return INFINITY;
    double span = g0 / (b->driver_stiffness * speed);
    double lo = t, hi = t, horizon = fmin(ctx->t_end, ctx->t_breakpoint);
    for (double ahead = AGING_SCAN_START * span;; ahead *= 2.0) {
        lo = hi;
        hi = t + ahead;
        if (hi > horizon)
            hi = horizon;
        if (margin_at(hi, &m) <= 0.0)
            break;
        if (hi >= horizon)
            return INFINITY;
    }
    gsl_function fn = {margin_at, &m};
    return bk_run_zero_after(ctx, &fn, lo, hi);
}

static double failure_time(run_ctx *ctx, size_t i, double t)
{
    if (ctx->model->blocks[i].law->n_state == 0)
        return coulomb_failure(ctx, i, t, bk_scene_static_threshold(&ctx->scene, i));
    return aging_failure(ctx, i, t);
}

/* Block i (stuck, next to no slipping block) leaves the integrators at t. */
void bk_run_make_quiet(run_ctx *ctx, size_t i, double t)
{
    bk_scene *scene = &ctx->scene;
    scene->island_of[i] = BK_NO_ISLAND;
    scene->slot[i] = BK_NO_SLOT;
    scene->x_ref[i] = scene->x[i];
    scene->v[i] = 0.0;
    bk_heap_set(&ctx->quiet, i, failure_time(ctx, i, t));
}
