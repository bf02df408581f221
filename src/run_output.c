/* What a run hands to its sink, and the books behind it: time-series rows, transitions (in
 * block order within an instant), the energy audit's running totals, statistics, and
 * checkpoints with the resume that continues from them.
 *
 * Energy.  The driver's work on a stuck block is the energy its driver spring gains (the
 * block does not move), so each stuck interval's work is known in closed form when it ends,
 * and a slipping block's work and dissipation are integrated by its island.  The totals are
 * kept as what has finished plus what is open, so an event costs O(1) in the books and
 * only a row (O(N) anyway) sums the open stuck intervals. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "capacity.h"
#include "output/layout.h"
#include "run_impl.h"

/* The [output] max_bytes guard counts what is written, event rows and transitions too:
 * their number is not known before the run. */
int bk_run_count_bytes(run_ctx *ctx, double bytes, double t)
{
    ctx->bytes_written += bytes;
    if (ctx->bytes_written <= ctx->max_bytes)
        return BK_OK;
    return BK_FAIL(ctx->err, BK_ERR_LIMIT,
                   "[output] max_bytes = %.3g B reached at t = %.17g s: %ld rows of %.3g B, %ld "
                   "transitions of %d B and %ld events of %d B; raise max_bytes, sample less often, or "
                   "write no event rows ([output] event_rows = false)",
                   ctx->max_bytes, t, ctx->stats->rows, ctx->row_bytes, ctx->stats->transitions,
                   BK_TRANSITION_RECORD_BYTES, ctx->events, BK_EVENT_RECORD_BYTES);
}

/* The row at t to the sink; the caller has checked progress and counted its bytes. */
static int send_row(run_ctx *ctx, double t, bk_row_kind kind)
{
    const bk_model *model = ctx->model;
    bk_scene *scene = &ctx->scene;
    double driver_pos = bk_driver_position(&model->driver, t);
    for (size_t i = 0; i < scene->n; ++i) {
        ctx->friction[i] = bk_scene_friction(scene, i, driver_pos);
        ctx->cof[i] = ctx->friction[i] / scene->normal[i];
    }
    if (model->n_friction_state > 0)
        for (size_t i = 0; i < scene->n; ++i)
            bk_scene_state_at_rest(scene, i, t, &ctx->state_out[model->blocks[i].state_offset]);
    bk_sample sample = {
        .t = t,
        .driver = driver_pos,
        .n_blocks = scene->n,
        .x = scene->x,
        .v = scene->v,
        .friction = ctx->friction,
        .cof = ctx->cof,
        .mode = scene->mode,
        .friction_state = model->n_friction_state ? ctx->state_out : NULL,
        .kinetic_energy = bk_model_kinetic_energy(model, scene->v),
        .elastic_energy = bk_model_elastic_energy(model, scene->x, driver_pos),
        .work_driver = ctx->total.work,
        .dissipation = ctx->total.friction,
        .damping_dissipation = ctx->total.damping,
        .is_event = (int)kind,
    };
    ctx->t_last_row = t;
    ctx->steps_since_row = 0;
    ctx->stats->rows++;
    ctx->restart_work += (double)ctx->scene.n;
    if (ctx->sink && ctx->sink->sample) {
        int rc = ctx->sink->sample(ctx->sink->self, &sample, ctx->err);
        if (rc != BK_OK)
            return rc < 0 ? rc : BK_ERR_SINK;
    }
    return BK_OK;
}

/* Rows can come without steps (all stuck, or dense sampling): a stop request and the wall
 * clock are checked before rows, and their bytes counted, before the first is written. */
static int before_rows(run_ctx *ctx, double t, int rows)
{
    int rc = bk_run_report_progress(ctx, t);
    return rc != BK_OK ? rc : bk_run_count_bytes(ctx, rows * ctx->row_bytes, t);
}

int bk_run_emit_sample(run_ctx *ctx, double t)
{
    int rc = before_rows(ctx, t, 1);
    return rc != BK_OK ? rc : send_row(ctx, t, BK_ROW_SAMPLE);
}

int bk_run_emit_event_rows(run_ctx *ctx, double t)
{
    int8_t *mode = ctx->scene.mode;
    size_t n_changed = ctx->n_changed;
    ctx->n_changed = 0;
    /* Both rows or neither: a stop between them would leave a file with half an instant. */
    int rc = before_rows(ctx, t, n_changed > 0 ? 2 : 1);
    /* The before row is the after row with the changed blocks' modes put back: nothing else
     * a row shows jumps at a transition. */
    for (size_t k = 0; k < n_changed; ++k) {
        size_t i = ctx->changed[k];
        int8_t after = mode[i];
        mode[i] = ctx->mode_before[i];
        ctx->mode_before[i] = after;
    }
    if (rc == BK_OK && n_changed > 0)
        rc = send_row(ctx, t, BK_ROW_BEFORE_TRANSITION);
    for (size_t k = 0; k < n_changed; ++k) {
        size_t i = ctx->changed[k];
        mode[i] = ctx->mode_before[i];
        ctx->mode_before[i] = BK_MODE_UNCHANGED;
    }
    return rc != BK_OK ? rc : send_row(ctx, t, BK_ROW_AFTER_TRANSITION);
}

static int writes_transitions(const run_ctx *ctx)
{
    return ctx->config->output.transitions && ctx->sink && ctx->sink->transition;
}

int bk_run_record_transition(run_ctx *ctx, double t, size_t i, bk_mode from, bk_mode to,
                             double applied_force)
{
    bk_scene *scene = &ctx->scene;
    if (t - ctx->last_transition[i] <= ctx->instant_window)
        ctx->instant_count[i]++;
    else
        ctx->instant_count[i] = 1;
    ctx->last_transition[i] = t;
    if (ctx->instant_count[i] > ctx->options.max_transitions_per_instant)
        return BK_FAIL(ctx->err, BK_ERR_ZENO,
                       "block %zu: more than %ld transitions within %.3g s at t = %.17g s "
                       "(chattering or Zeno behaviour; last %s -> %s, applied force %.6g N, "
                       "static threshold %.6g N); see [solver] max_transitions_per_instant",
                       i, ctx->options.max_transitions_per_instant, ctx->instant_window, t,
                       bk_mode_name(from), bk_mode_name(to), applied_force,
                       bk_scene_static_threshold(scene, i));
    ctx->stats->transitions++;
    ctx->steps_since_row = 0;
    ctx->restart_work += 1.0;
    if (ctx->mode_before && ctx->mode_before[i] == BK_MODE_UNCHANGED) {
        ctx->mode_before[i] = (int8_t)from;
        ctx->changed[ctx->n_changed++] = i;
    }
    bk_transition record = {
        .t = t,
        .block = (int32_t)i,
        .from = (int8_t)from,
        .to = (int8_t)to,
        .x = scene->x[i],
        .v = scene->v[i],
        .force = applied_force,
    };
    /* The catalog takes them in the order /transitions holds them, so that it is the
     * catalog rebuilt from that table bit for bit. */
    int written = writes_transitions(ctx);
    if (!written && !ctx->catalog)
        return BK_OK;
    int rc = written ? bk_run_count_bytes(ctx, BK_TRANSITION_RECORD_BYTES, t) : BK_OK;
    if (rc != BK_OK)
        return rc;
    if (ctx->n_instant > 0 && t != ctx->t_instant && (rc = bk_run_flush_instant(ctx)) != BK_OK)
        return rc;
    bk_transition *instant = bk_grow_array(ctx->instant, &ctx->instant_capacity, ctx->n_instant + 1,
                                           sizeof *instant, 16);
    if (!instant)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the transitions of t = %.17g s", t);
    ctx->instant = instant;
    ctx->t_instant = t;
    ctx->instant[ctx->n_instant++] = record;
    return BK_OK;
}

int bk_run_flush_instant(run_ctx *ctx)
{
    size_t n = ctx->n_instant;
    ctx->n_instant = 0;
    /* Insertion sort by block, stable: one block's transitions keep their order, and an
     * instant holds a handful (or a uniform chain's synchronous slip, in order already). */
    for (size_t k = 1; k < n; ++k) {
        bk_transition moving = ctx->instant[k];
        size_t j = k;
        for (; j > 0 && ctx->instant[j - 1].block > moving.block; --j)
            ctx->instant[j] = ctx->instant[j - 1];
        ctx->instant[j] = moving;
    }
    int written = writes_transitions(ctx);
    for (size_t k = 0; k < n; ++k) {
        int rc = bk_run_catalog_transition(ctx, &ctx->instant[k]);
        if (rc == BK_OK && written)
            rc = ctx->sink->transition(ctx->sink->self, &ctx->instant[k], ctx->err);
        if (rc != BK_OK)
            return rc < 0 ? rc : BK_ERR_SINK;
    }
    return BK_OK;
}

void bk_run_leave_stuck(run_ctx *ctx, size_t i, double t)
{
    double driver_pos = bk_driver_position(&ctx->model->driver, t);
    ctx->closed.work += bk_scene_driver_spring_energy(&ctx->scene, i, driver_pos) - ctx->spring_energy_ref[i];
}

void bk_run_enter_stuck(run_ctx *ctx, size_t i, double t)
{
    double driver_pos = bk_driver_position(&ctx->model->driver, t);
    ctx->spring_energy_ref[i] = bk_scene_driver_spring_energy(&ctx->scene, i, driver_pos);
}

void bk_run_energy_totals(run_ctx *ctx, double t, const bk_energy *islands)
{
    const bk_scene *scene = &ctx->scene;
    double driver_pos = bk_driver_position(&ctx->model->driver, t);
    double open = 0.0;
    for (size_t i = 0; i < scene->n; ++i)
        if (bk_scene_stuck(scene, i))
            open += bk_scene_driver_spring_energy(scene, i, driver_pos) - ctx->spring_energy_ref[i];
    ctx->total = ctx->closed;
    bk_energy_add(&ctx->total, islands);
    ctx->total.work += open;
}

void bk_run_rebase_energy(run_ctx *ctx, double t)
{
    bk_scene *scene = &ctx->scene;
    ctx->closed = ctx->total;
    for (size_t i = 0; i < scene->n; ++i)
        if (bk_scene_stuck(scene, i)) {
            bk_run_enter_stuck(ctx, i, t);
            if (scene->island_of[i] == BK_NO_ISLAND)
                bk_scene_age(scene, i, t);
        }
}

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
    if (ctx->sink && ctx->sink->checkpoint && now - ctx->wall_checkpoint >= ctx->checkpoint_wall_interval) {
        ctx->wall_checkpoint = now;
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
            .next_sample = ctx->next_sample,
            .work_driver = ctx->total.work,
            .dissipation = ctx->total.friction,
            .damping_dissipation = ctx->total.damping,
            .elastic_initial = ctx->elastic0,
            .kinetic_initial = ctx->kinetic0,
            .t_last_row = ctx->t_last_row,
            .steps_since_row = ctx->steps_since_row,
            .catalog = bk_run_catalog_save(ctx),
        };
        cp.stats = *ctx->stats;
        bk_run_collect_stats(ctx, &cp.stats, ctx->cpu0);
        rc = ctx->sink->checkpoint(ctx->sink->self, &cp, ctx->err);
        if (rc != BK_OK)
            return rc < 0 ? rc : BK_ERR_SINK;
    }
    /* A checkpoint is a restart of everything, as a resumed run starts. */
    return bk_run_partition_all(ctx, t);
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
