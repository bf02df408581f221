/* The run loop, shared by every solver back-end: a scheduler over independent islands.
 *
 *   t = 0: resolve initial modes, partition the chain into islands and quiet blocks
 *          (scene.h), emit the first row.
 *   repeat until t_end, taking whichever comes first:
 *     an island lagging behind everything else: one step of its integrator, which may
 *       find its next event (a root, or a stop hidden inside the step, located on the
 *       step's interpolant);
 *     an island's event: the mode machine decides, and only that island (and a neighbour
 *       it merges with) is rebuilt and restarted;
 *     a quiet block's breakaway, known in closed form: it starts an island;
 *     a sample time, a checkpoint or t_end: every island's state there (dense output).
 *
 * Islands are integrated to different times, each by its own back-end instance, so a
 * cluster far away does not force another's step sizes.  The earliest pending event is
 * always handled first, and an island is stepped only while it lags behind every pending
 * event, quiet failure and output time; so every island's last step contains the time of
 * the event being handled, and a merge finds the other island's state there.  An event
 * costs time in proportion to the islands it touches and log N for the queues. */
#include "bksim/run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_errno.h>

#include "method_choice.h"
#include "layout.h"
#include "prescribed.h"
#include "run_ctx.h"

#define PI 3.14159265358979323846

/* An automatic restart point once the work since the last one reaches checkpoint_work: on a
 * fine grid of time just after everything settled so far, so that every island's last step
 * ends there or contains it.  Work and times are the run's own, the same in every run of the
 * config, so a resumed run restarts where the uninterrupted one does. */
static void plan_restart(run_ctx *ctx)
{
    if (!(ctx->checkpoint_work > 0.0) || ctx->restart_work < ctx->checkpoint_work || isfinite(ctx->t_restart))
        return;
    double grid = ctx->t_end * 0x1p-20;
    double t = (floor(ctx->t_settled / grid) + 1.0) * grid;
    ctx->t_restart = t > ctx->t_settled ? t : ctx->t_settled + grid;
}

static double sample_time(const run_ctx *ctx, long k)
{
    if (ctx->interval <= 0.0)
        return ctx->t_end;
    double t = (double)k * ctx->interval;
    return t >= ctx->t_end - 1e-9 * ctx->interval ? ctx->t_end : t;
}

/* The end is a restart point of a run that has them, written as a checkpoint whatever the wall
 * clock says: the state a later run starts from (--init-from), and where a longer run of the
 * same scene goes on (--restart with a later t_end). */
static int ends_with_checkpoint(const run_ctx *ctx)
{
    return bk_run_has_restart_points(ctx);
}

/* The sample a run continued past t_end emits first: the first on the grid after t_end (a
 * row at t_end, sample or event, is written now; a grid time the last row stood in for,
 * within rounding before it, is still to come at its own time). */
static long next_sample_after_end(const run_ctx *ctx)
{
    if (ctx->interval <= 0.0)
        return 1; /* the only sample left is the end's */
    double k = floor(ctx->t_end / ctx->interval);
    while (k * ctx->interval <= ctx->t_end)
        k += 1.0;
    while (k > 1.0 && (k - 1.0) * ctx->interval > ctx->t_end)
        k -= 1.0;
    return (long)k;
}

/* Skip a sample that falls exactly on an event row already written. */
static void skip_sample_at(run_ctx *ctx, double t)
{
    if (ctx->next_sample >= 0 && sample_time(ctx, ctx->next_sample) == t)
        ctx->next_sample = t >= ctx->t_end ? -1 : ctx->next_sample + 1;
}

/* The end of an instant: its transitions go out in block order, and its event row. */
static int close_instant(run_ctx *ctx)
{
    int rc = ctx->n_instant > 0 ? bk_run_flush_instant(ctx) : BK_OK;
    if (rc != BK_OK || isnan(ctx->t_row_due))
        return rc;
    double t = ctx->t_row_due;
    ctx->t_row_due = NAN;
    if ((rc = bk_run_unpack_all(ctx, t)) != BK_OK || (rc = bk_run_emit_event_rows(ctx, t)) != BK_OK)
        return rc;
    skip_sample_at(ctx, t);
    return BK_OK;
}

enum action { STEP, EVENT, QUIET, SAMPLE, STOP };

/* From t to t_end (see the top of this file). */
static int schedule(run_ctx *ctx)
{
    for (;;) {
        plan_restart(ctx);
        double t_sample = ctx->next_sample >= 0 ? sample_time(ctx, ctx->next_sample) : INFINITY;
        double t_stop = bk_run_stop_time(ctx);
        double t_barrier = t_sample < t_stop ? t_sample : t_stop;
        double t_quiet = bk_heap_empty(&ctx->quiet) ? INFINITY : bk_heap_top_key(&ctx->quiet);
        double t_local = t_quiet < t_barrier ? t_quiet : t_barrier;
        enum action action;
        double t_action;
        size_t id = BK_HEAP_ABSENT;
        int pending = 0;
        double key = INFINITY;
        if (!bk_heap_empty(&ctx->island_queue)) {
            id = bk_heap_top(&ctx->island_queue);
            key = bk_heap_top_key(&ctx->island_queue);
            pending = ctx->islands[id]->pending;
        }
        /* Events before output at the same instant: a row there shows what happened. */
        if (id != BK_HEAP_ABSENT && !pending && key < t_local) {
            action = STEP;
            t_action = key;
        } else if (id != BK_HEAP_ABSENT && pending && key <= t_local) {
            action = EVENT;
            t_action = key;
        } else if (t_quiet <= t_barrier) {
            action = QUIET;
            t_action = t_quiet;
        } else {
            /* A sample at a checkpoint is written before it, as the run reaches it. */
            action = t_sample < t_stop || (t_sample == t_stop && t_stop < ctx->t_end) ? SAMPLE : STOP;
            t_action = t_barrier;
        }
        /* An instant ends when something else than an event at its time comes next. */
        double t_open = ctx->n_instant > 0 ? ctx->t_instant : ctx->t_row_due;
        int same_instant = (action == EVENT || action == QUIET) && t_action == t_open;
        if ((ctx->n_instant > 0 || !isnan(ctx->t_row_due)) && !same_instant) {
            int rc = close_instant(ctx);
            if (rc != BK_OK)
                return rc;
            continue; /* the row may have taken the sample */
        }
        int rc = BK_OK;
        ctx->t_settled = t_action;
        switch (action) {
        case STEP:
            rc = bk_run_island_step(ctx, id);
            break;
        case EVENT:
            rc = bk_run_island_event(ctx, id);
            if (rc == BK_OK)
                rc = bk_run_report_progress(ctx, t_action);
            break;
        case QUIET:
            rc = bk_run_quiet_failures(ctx, t_action);
            if (rc == BK_OK)
                rc = bk_run_report_progress(ctx, t_action);
            break;
        case SAMPLE:
            if ((rc = bk_run_unpack_all(ctx, t_action)) == BK_OK &&
                (rc = bk_run_emit_sample(ctx, t_action)) == BK_OK)
                ctx->next_sample++;
            break;
        case STOP:
            if (t_stop < ctx->t_end) {
                /* A driver breakpoint restarts everything on the next segment's line (its
                 * quiet blocks' failure times too, so the next breakpoint is set first). */
                if (t_stop == ctx->t_breakpoint)
                    ctx->t_breakpoint = bk_driver_next_breakpoint(&ctx->model->driver, t_stop);
                rc = bk_run_restart_all(ctx, t_stop, t_stop == bk_run_checkpoint_time(ctx));
                break;
            }
            if ((rc = bk_run_unpack_all(ctx, ctx->t_end)) != BK_OK)
                return rc;
            /* The final row, unless an event row at t_end took its place. */
            long after_end = next_sample_after_end(ctx);
            /* A run resumed from its own end's checkpoint (killed before it finished) has that
             * row already. */
            if (ctx->next_sample >= 0 && ctx->t_last_row < ctx->t_end)
                rc = bk_run_emit_sample(ctx, ctx->t_end);
            ctx->next_sample = -1;
            if (rc == BK_OK && ends_with_checkpoint(ctx))
                rc = bk_run_write_checkpoint(ctx, ctx->t_end, after_end);
            return rc;
        }
        if (rc != BK_OK)
            return rc;
    }
}

/* --- set-up ---------------------------------------------------------------------------- */

/* Fill the auto tolerances, step limit and chattering window from the model's scales. */
static void resolve_scales(run_ctx *ctx)
{
    const bk_model *model = ctx->model;
    bk_solver_options *opt = &ctx->options;
    double omega = bk_model_max_angular_frequency(model);
    double length = 0.0, force = 0.0;
    for (size_t i = 0; i < model->n_blocks; ++i) {
        double stiffness = bk_model_block_stiffness(model, i);
        double driver_speed = fabs(model->driver.velocity) > 0.0 ? fabs(model->driver.velocity) : 1e-3;
        double threshold = ctx->scene.can_stick[i] ? bk_scene_static_threshold(&ctx->scene, i)
                                                   : fabs(bk_scene_sliding_force(&ctx->scene, i, driver_speed));
        if (threshold > force)
            force = threshold;
        if (stiffness > 0.0 && threshold / stiffness > length)
            length = threshold / stiffness;
    }
    if (!(length > 0.0))
        length = 1e-3;
    if (!(force > 0.0))
        force = 1.0;
    double speed = fabs(model->driver.velocity);
    double ring_speed = omega > 0.0 ? length * omega : 0.0;
    double velocity_scale = speed > 0.0 && ring_speed > 0.0 ? fmin(speed, ring_speed)
                            : speed > 0.0                    ? speed
                            : ring_speed > 0.0               ? ring_speed
                                                             : 1e-3;
    ctx->atol_x = isnan(opt->atol_x) ? opt->rtol * 1e-3 * length : opt->atol_x;
    ctx->atol_v = isnan(opt->atol_v) ? opt->rtol * 1e-3 * velocity_scale : opt->atol_v;
    double state_scale = 0.0;
    for (size_t k = 0; k < model->n_friction_state; ++k)
        state_scale = fmax(state_scale, fabs(ctx->scene.state[k]));
    ctx->atol_state = opt->rtol * 1e-3 * (state_scale > 0.0 ? state_scale : 1.0);
    ctx->atol_energy = ctx->atol_x * force;
    double scale = bk_model_step_time_scale(model);
    /* Short beside everything the scene resolves, long beside what explicit methods step. */
    ctx->scene.balance_time = isfinite(scale) ? scale / 8.0 : 1e-3 * ctx->t_end;
    if (isnan(opt->max_step))
        opt->max_step = isfinite(scale) ? scale / 8.0 : 0.0;
    ctx->instant_window = !isnan(opt->instant_window) ? opt->instant_window
                          : isfinite(scale)            ? 1e-6 * scale
                                                       : 1e-12 * ctx->t_end;
}

static void free_ctx(run_ctx *ctx)
{
    bk_run_ruptures_free(ctx);
    bk_run_catalog_free(ctx);
    bk_run_islands_free(ctx);
    bk_run_segments_free(ctx);
    bk_run_partition_free(ctx);
    bk_scene_free(&ctx->scene);
    free(ctx->spring_energy_ref);
    free(ctx->instant);
    free(ctx->friction);
    free(ctx->cof);
    free(ctx->state_out);
    free(ctx->last_transition);
    free(ctx->instant_count);
    free(ctx->mode_before);
    free(ctx->changed);
}

/* Modes at t = 0: moving blocks slip their way, resting ones by the machine. */
static int initial_modes(run_ctx *ctx, int *any_transition)
{
    bk_scene *scene = &ctx->scene;
    *any_transition = 0;
    for (size_t i = 0; i < scene->n; ++i) {
        if (!scene->can_stick[i]) {
            scene->mode[i] = scene->v[i] < 0.0 ? BK_MODE_SLIP_NEG : BK_MODE_SLIP_POS;
            scene->from_rest[i] = 0;
            continue;
        }
        if (scene->v[i] != 0.0) {
            scene->mode[i] = scene->v[i] > 0.0 ? BK_MODE_SLIP_POS : BK_MODE_SLIP_NEG;
            scene->from_rest[i] = 0;
            continue;
        }
        scene->mode[i] = BK_MODE_STICK;
        bk_run_enter_stuck(ctx, i, 0.0);
        int rc = bk_run_apply_event(ctx, 0.0, i, BK_EVENT_STOP);
        if (rc < 0)
            return rc;
        *any_transition |= rc;
    }
    return BK_OK;
}

int bk_run(const bk_config *config, const bk_sink *sink, bk_run_stats *stats,
           bk_progress_fn progress, void *progress_user, bk_error *err)
{
    return bk_run_from(config, NULL, sink, stats, progress, progress_user, err);
}

int bk_run_from(const bk_config *config, const bk_checkpoint *from, const bk_sink *sink,
                bk_run_stats *stats, bk_progress_fn progress, void *progress_user, bk_error *err)
{
    if (config->prescribed) {
        if (from)
            return BK_FAIL(err, BK_ERR_INVALID, "prescribed-motion scenes have no checkpoints");
        return bk_run_prescribed(config, sink, stats, progress, progress_user, err);
    }
    double wall0 = bk_run_wall_seconds();
    clock_t cpu0 = clock();
    gsl_set_error_handler_off();
    run_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    bk_run_stats local_stats;
    memset(&local_stats, 0, sizeof local_stats);
    ctx.config = config;
    ctx.model = config->model;
    ctx.sink = sink;
    ctx.err = err;
    ctx.stats = stats ? stats : &local_stats;
    ctx.progress = progress;
    ctx.progress_user = progress_user;
    ctx.options = config->solver;
    ctx.t_end = config->t_end;
    ctx.interval = config->output.interval;
    ctx.event_rows = config->output.event_rows;
    ctx.next_sample = 0;
    ctx.wall_start = wall0;
    ctx.cpu0 = (double)cpu0;
    ctx.checkpoint_interval = config->output.checkpoint_interval;
    ctx.next_checkpoint = 1;
    ctx.checkpoint_wall_interval = config->output.checkpoint_wall_interval;
    ctx.wall_checkpoint = wall0;
    ctx.checkpoint_work = config->output.checkpoint_work;
    ctx.t_restart = INFINITY;
    ctx.t_breakpoint = bk_driver_next_breakpoint(&config->model->driver, from ? from->t : 0.0);
    ctx.t_row_due = NAN;
    ctx.max_bytes = config->output.max_bytes > 0.0 ? config->output.max_bytes : INFINITY;
    ctx.row_bytes = bk_output_row_bytes(config->output.fields, config->model->n_blocks,
                                        config->model->n_friction_state, bk_model_is_damped(config->model));
    ctx.t_instant = NAN;
    memset(ctx.stats, 0, sizeof *ctx.stats);
    snprintf(ctx.stats->method, sizeof ctx.stats->method, "%s", config->solver.method);

    if (bk_scene_init(&ctx.scene, ctx.model, config->solver.detect_velocity_extrema) != 0)
        return BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu blocks", ctx.model->n_blocks);
    const char *method = bk_choose_method(config, &ctx.scene);
    ctx.backend = bk_solver_backend_find(method);
    if (!ctx.backend) {
        bk_scene_free(&ctx.scene);
        return BK_FAIL(err, BK_ERR_CONFIG, "unknown solver method '%s'", method);
    }
    if (method != config->solver.method)
        snprintf(ctx.stats->method, sizeof ctx.stats->method, "%s (auto)", method);
    ctx.segment_blocks = bk_choose_segments(config, &ctx.scene, ctx.backend);
    size_t n = ctx.model->n_blocks;
    ctx.scene.full_layout = ctx.backend->wants_full_layout;
    ctx.spring_energy_ref = calloc(n, sizeof *ctx.spring_energy_ref);
    ctx.friction = calloc(n, sizeof *ctx.friction);
    ctx.cof = calloc(n, sizeof *ctx.cof);
    ctx.state_out = calloc(ctx.model->n_friction_state + 1, sizeof *ctx.state_out);
    ctx.last_transition = malloc(n * sizeof *ctx.last_transition);
    ctx.instant_count = calloc(n, sizeof *ctx.instant_count);
    int rc = BK_OK;
    if (!ctx.spring_energy_ref || !ctx.friction || !ctx.cof || !ctx.state_out ||
        !ctx.last_transition || !ctx.instant_count || bk_run_islands_init(&ctx) != 0 ||
        bk_run_partition_init(&ctx) != 0) {
        rc = BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu blocks", n);
        goto done;
    }
    if ((rc = bk_run_segments_init(&ctx)) != BK_OK)
        goto done;
    for (size_t i = 0; i < n; ++i)
        ctx.last_transition[i] = -INFINITY;
    if (ctx.event_rows) {
        ctx.mode_before = malloc(n * sizeof *ctx.mode_before);
        ctx.changed = malloc(n * sizeof *ctx.changed);
        if (!ctx.mode_before || !ctx.changed) {
            rc = BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu blocks", n);
            goto done;
        }
        memset(ctx.mode_before, BK_MODE_UNCHANGED, n * sizeof *ctx.mode_before);
    }
    /* Scales come from the initial state in a resumed run too, so both runs use the same. */
    resolve_scales(&ctx);
    if ((rc = bk_run_catalog_init(&ctx, from)) != BK_OK || (rc = bk_run_ruptures_init(&ctx, from)) != BK_OK)
        goto done;

    if (from) {
        ctx.t_resumed = ctx.t_progress = ctx.t_settled = from->t;
        if ((rc = bk_run_resume(&ctx, from)) != BK_OK || (rc = bk_run_partition_all(&ctx, from->t)) != BK_OK)
            goto done;
    } else {
        int moved;
        if ((rc = initial_modes(&ctx, &moved)) != BK_OK)
            goto done;
        double driver0 = bk_driver_position(&ctx.model->driver, 0.0);
        ctx.elastic0 = bk_model_elastic_energy(ctx.model, ctx.scene.x, driver0);
        ctx.kinetic0 = bk_model_kinetic_energy(ctx.model, ctx.scene.v);
        if ((rc = bk_run_partition_all(&ctx, 0.0)) != BK_OK ||
            (rc = bk_run_flush_instant(&ctx)) != BK_OK || (rc = bk_run_unpack_all(&ctx, 0.0)) != BK_OK ||
            (rc = (moved ? bk_run_emit_event_rows(&ctx, 0.0) : bk_run_emit_sample(&ctx, 0.0))) != BK_OK)
            goto done;
        ctx.next_sample = 1;
    }
    rc = schedule(&ctx);
    if (rc == BK_OK)
        rc = close_instant(&ctx);
    if (rc == BK_OK)
        rc = bk_run_catalog_finish(&ctx, ctx.t_end);
    if (rc == BK_OK)
        rc = bk_run_ruptures_finish(&ctx, ctx.t_end);

done:
    bk_run_collect_stats(&ctx, ctx.stats, (double)cpu0);
    if (ctx.scene.x && ctx.spring_energy_ref) {
        bk_run_stats *st = ctx.stats;
        double d = bk_driver_position(&ctx.model->driver, ctx.t_last_row);
        st->work_driver = ctx.total.work;
        st->dissipation = ctx.total.friction;
        st->damping_dissipation = ctx.total.damping;
        st->elastic_change = bk_model_elastic_energy(ctx.model, ctx.scene.x, d) - ctx.elastic0;
        st->kinetic_change = bk_model_kinetic_energy(ctx.model, ctx.scene.v) - ctx.kinetic0;
        double scale = fmax(fmax(fmax(fabs(st->work_driver), fabs(st->dissipation)),
                                 fmax(fabs(st->elastic_change), fabs(st->kinetic_change))),
                            fabs(st->damping_dissipation));
        double residual = st->work_driver - st->elastic_change - st->kinetic_change - st->dissipation -
                          st->damping_dissipation;
        st->energy_residual = scale > 0.0 ? residual / scale : 0.0;
        if (rc == BK_OK && !isfinite(st->energy_residual))
            rc = BK_FAIL(err, BK_ERR_NUMERIC,
                         "the energy audit overflowed at t = %.17g s (driver work %g J, elastic change %g J, "
                         "kinetic change %g J, dissipation %g J, by dashpots %g J): the motion's scale is "
                         "beyond double precision",
                         ctx.t_last_row, st->work_driver, st->elastic_change, st->kinetic_change,
                         st->dissipation, st->damping_dissipation);
    }
    free_ctx(&ctx);
    return rc;
}
