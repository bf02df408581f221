/* Restart points and statistics: every island restarted at a restart point (written as a
 * checkpoint when the wall clock says), the state of a checkpoint put back into the chain
 * when a run resumes, and the run's statistics with a resumed run's included. */
#include <math.h>
#include <string.h>
#include <time.h>

#include "run_ctx.h"

void bk_run_collect_stats(const run_ctx *ctx, bk_run_stats *stats, double cpu0)
{
    const bk_run_stats *base = &ctx->base;
    bk_solver_counters c;
    bk_run_solver_counters(ctx, &c);
    stats->steps = base->steps + c.steps;
    stats->rhs_evals = base->rhs_evals + c.rhs_evals;
    stats->root_evals = base->root_evals + c.root_evals;
    stats->err_test_fails = base->err_test_fails + c.err_test_fails;
    stats->nonlin_iters = base->nonlin_iters + c.nonlin_iters;
    stats->t_reached = ctx->t_last_row;
    stats->wall_time = base->wall_time + (bk_run_wall_seconds() - ctx->wall_start);
    stats->cpu_time = base->cpu_time + (double)(clock() - (clock_t)cpu0) / CLOCKS_PER_SEC;
}

int bk_run_restart_all(run_ctx *ctx, double t, int restart_point)
{
    int rc = bk_run_unpack_all(ctx, t);
    if (rc != BK_OK)
        return rc;
    bk_run_rebase_energy(ctx, t);
    if (!restart_point)
        return bk_run_partition_all(ctx, t);
    ctx->next_checkpoint++;
    ctx->restart_work = 0.0;
    ctx->t_restart = INFINITY;
    double now = bk_run_wall_seconds();
    if (ctx->sink && ctx->sink->checkpoint &&
        (ctx->stop_at_restart || now - ctx->wall_checkpoint >= ctx->checkpoint_wall_interval)) {
        ctx->wall_checkpoint = now;
        if ((rc = bk_run_write_checkpoint(ctx, t, ctx->next_sample)) != BK_OK)
            return rc;
        if (ctx->stop_at_restart)
            return BK_FAIL(ctx->err, BK_ERR_INTERRUPTED,
                           "run interrupted at t = %.17g s, its restart point, written as a checkpoint "
                           "%.2g s after the request to stop",
                           t, now - ctx->wall_stop_asked);
    }
    /* A checkpoint is a restart of everything, as a resumed run starts. */
    return bk_run_partition_all(ctx, t);
}

int bk_run_write_checkpoint(run_ctx *ctx, double t, long next_sample)
{
    bk_scene *scene = &ctx->scene;
    bk_checkpoint cp = {
        .t = t,
        .n_blocks = scene->n,
        .n_state = ctx->model->n_friction_state,
        .mode = scene->mode,
        .x = scene->x,
        .v = scene->v,
        .state = scene->state,
        .t_switch = scene->t_switch,
        .from_rest = scene->from_rest,
        .extremum_armed = scene->extremum_armed,
        .last_transition = ctx->last_transition,
        .instant_count = ctx->instant_count,
        .next_sample = next_sample,
        .work_driver = ctx->total.work,
        .dissipation = ctx->total.friction,
        .damping_dissipation = ctx->total.damping,
        .elastic_initial = ctx->elastic0,
        .kinetic_initial = ctx->kinetic0,
        .t_last_row = ctx->t_last_row,
        .steps_since_row = ctx->steps_since_row,
    };
    int rc = bk_run_catalog_save(ctx, &cp.catalog);
    if (rc != BK_OK)
        return rc;
    cp.stats = *ctx->stats;
    bk_run_collect_stats(ctx, &cp.stats, ctx->cpu0);
    rc = ctx->sink->checkpoint(ctx->sink->self, &cp, ctx->err);
    return rc == BK_OK ? BK_OK : rc < 0 ? rc : BK_ERR_SINK;
}

int bk_run_resume(run_ctx *ctx, const bk_checkpoint *cp)
{
    bk_scene *scene = &ctx->scene;
    size_t n = scene->n, n_state = ctx->model->n_friction_state;
    if (cp->n_blocks != n || cp->n_state != n_state)
        return BK_FAIL(ctx->err, BK_ERR_INVALID,
                       "checkpoint of %zu blocks and %zu friction states does not fit this config (%zu, %zu)",
                       cp->n_blocks, cp->n_state, n, n_state);
    memcpy(scene->mode, cp->mode, n * sizeof *scene->mode);
    memcpy(scene->x, cp->x, n * sizeof *scene->x);
    memcpy(scene->x_ref, cp->x, n * sizeof *scene->x_ref);
    memcpy(scene->v, cp->v, n * sizeof *scene->v);
    memcpy(scene->state, cp->state, n_state * sizeof *scene->state);
    memcpy(scene->t_switch, cp->t_switch, n * sizeof *scene->t_switch);
    memcpy(scene->from_rest, cp->from_rest, n * sizeof *scene->from_rest);
    memcpy(scene->extremum_armed, cp->extremum_armed, n * sizeof *scene->extremum_armed);
    memcpy(ctx->last_transition, cp->last_transition, n * sizeof *ctx->last_transition);
    memcpy(ctx->instant_count, cp->instant_count, n * sizeof *ctx->instant_count);
    for (size_t i = 0; i < n; ++i)
        scene->state_time[i] = cp->t;
    ctx->total = (bk_energy){cp->work_driver, cp->dissipation, cp->damping_dissipation};
    bk_run_rebase_energy(ctx, cp->t);
    ctx->elastic0 = cp->elastic_initial;
    ctx->kinetic0 = cp->kinetic_initial;
    ctx->next_sample = cp->next_sample;
    ctx->t_last_row = cp->t_last_row;
    ctx->steps_since_row = cp->steps_since_row;
    ctx->base = cp->stats;
    *ctx->stats = cp->stats;
    if (ctx->checkpoint_interval > 0.0)
        ctx->next_checkpoint = (long)llround(cp->t / ctx->checkpoint_interval) + 1;
    return BK_OK;
}
