/* What happens to the partition's islands and quiet blocks (run_islands.c holds them): an
 * island steps with its own integrator and finds its next event (a root, or a stop hidden
 * inside the step, located on the step's interpolant); at an event the mode machine
 * decides, and only that island (and a neighbour it may merge with) is rebuilt
 * (run_partition.c); a quiet block breaks away at a time known in closed form
 * (run_quiet.c), and every block failing at that instant slips together. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_roots.h>

#include "run_ctx.h"

/* Quiet blocks whose failure times agree to this many ulps fail at one instant (a uniform
 * chain's blocks all do). */
#define SIMULTANEOUS_EPS (8.0 * DBL_EPSILON)

static double island_key(const run_island *isl)
{
    return isl->pending ? isl->t_event : isl->t_reached;
}

/* The stop root function of a slipping block on the island's last step's interpolant. */
static double stop_function(double t, void *user)
{
    bk_block_probe *probe = user;
    const bk_scene *scene = &probe->ctx->scene;
    size_t i = probe->block;
    const double *y = bk_run_probe_state(probe, t);
    if (!y)
        return 0.0;
    double slip_rate = (double)scene->mode[i] * y[scene->slot[i] + 1];
    double since = t - scene->t_switch[i];
    if (scene->from_rest[i] && since <= 0.0)
        return 1.0; /* the limit s a > 0 at the start of a slip from rest */
    return scene->from_rest[i] ? slip_rate / since : slip_rate;
}

/* Locate the stop of block i hidden inside the island's last step before t_root. */
static int locate_hidden_stop(run_ctx *ctx, run_island *isl, size_t i, double t_root, double *t_stop)
{
    double lo, hi;
    ctx->backend->last_step(isl->solver, &lo, &hi);
    if (lo < isl->t_resume)
        lo = isl->t_resume;
    bk_block_probe probe = {ctx, isl, i, BK_OK};
    gsl_function fn = {stop_function, &probe};
    double f_lo = stop_function(lo, &probe), f_hi = stop_function(t_root, &probe);
    if (probe.status != BK_OK)
        return probe.status;
    if (f_hi >= 0.0 || f_lo <= 0.0) {
        *t_stop = f_hi >= 0.0 ? t_root : lo;
        return BK_OK;
    }
    /* The upper end is past the zero: the state there has s v <= 0, as at a found root. */
    *t_stop = bk_run_zero_after(ctx, &fn, lo, t_root);
    return probe.status;
}

/* The event an island's step just found at t_reached: a root (from_root), or a slipping
 * block's velocity past zero at a step end although no root fired (a stop the root
 * functions could not see, e.g. one masked at a restart).  A slip-rate minimum below zero,
 * or that velocity, means the stop hid inside the step: the event moves back to it. */
static int find_event(run_ctx *ctx, run_island *isl, double t_root, int from_root)
{
    const bk_scene *scene = &ctx->scene;
    const bk_island *island = &isl->island;
    size_t R = scene->roots_per_block, n_roots = bk_island_n_roots(island);
    if (from_root) {
        if (ctx->backend->root_info(isl->solver, isl->found) != BK_OK)
            return BK_FAIL(ctx->err, BK_ERR_SOLVER, "cannot read root information at t = %.17g s", t_root);
    } else {
        memset(isl->found, 0, n_roots * sizeof *isl->found);
    }
    double t_hidden = t_root;
    size_t hidden_block = SIZE_MAX;
    for (size_t k = 0; k < island->len; ++k) {
        size_t i = bk_island_block(island, k);
        if (bk_scene_stuck(scene, i) || !scene->can_stick[i] || isl->found[R * k + BK_ROOT_MAIN])
            continue;
        if (from_root && !isl->found[R * k + BK_ROOT_EXTREMUM])
            continue;
        double slip_rate = (double)scene->mode[i] * isl->y[scene->slot[i] + 1];
        if (from_root ? slip_rate > 0.0 : slip_rate >= 0.0)
            continue;
        double t_stop = t_root;
        int rc = locate_hidden_stop(ctx, isl, i, t_root, &t_stop);
        if (rc != BK_OK)
            return rc;
        if (t_stop < t_hidden || hidden_block == SIZE_MAX) {
            t_hidden = t_stop;
            hidden_block = i;
        }
    }
    isl->pending = 1;
    isl->from_root = from_root;
    isl->hidden_block = hidden_block;
    isl->t_event = hidden_block != SIZE_MAX ? t_hidden : t_root;
    return BK_OK;
}

static int check_finite(run_ctx *ctx, const run_island *isl, double t)
{
    for (size_t k = 0; k < isl->island.n_y; ++k)
        if (!isfinite(isl->y[k]))
            return BK_FAIL(ctx->err, BK_ERR_NUMERIC,
                           "non-finite value in the solution at t = %.17g s (component %zu)", t, k);
    return BK_OK;
}

/* A slipping block whose velocity is past zero at a step end without a root. */
static int missed_stop(const run_ctx *ctx, const run_island *isl)
{
    const bk_scene *scene = &ctx->scene;
    for (size_t k = 0; k < isl->island.n_active; ++k) {
        size_t i = isl->island.active[k];
        if (scene->can_stick[i] && (double)scene->mode[i] * isl->y[scene->slot[i] + 1] < 0.0)
            return 1;
    }
    return 0;
}

int bk_run_island_step(run_ctx *ctx, size_t id)
{
    run_island *isl = ctx->islands[id];
    double t_reached;
    int segmented = ctx->scene.segmented;
    int rc = segmented ? bk_run_segment_stop(ctx, isl) : BK_OK;
    if (rc != BK_OK)
        return rc;
    int step = ctx->backend->step(isl->solver, &t_reached, isl->y, ctx->err);
    if (step < 0)
        return step;
    isl->stepped = 1;
    isl->t_reached = t_reached;
    ctx->restart_work += (double)isl->island.len;
    if ((rc = check_finite(ctx, isl, t_reached)) != BK_OK ||
        (segmented && (rc = bk_run_segment_stepped(ctx, isl)) != BK_OK))
        return rc;
    /* The hang guard counts steps of the whole chain: segments share it. */
    long allowed = ctx->options.max_steps * (segmented ? (long)ctx->live_islands : 1);
    if (++ctx->steps_since_row > allowed)
        return BK_FAIL(ctx->err, BK_ERR_MAX_STEPS,
                       "more than %ld solver steps since the last output row or transition "
                       "(t = %.17g s, now at t = %.17g s); raise [solver] max_steps or loosen rtol",
                       allowed, ctx->t_last_row, t_reached);
    if (step == BK_STEP_ROOT) {
        rc = find_event(ctx, isl, t_reached, 1);
    } else {
        if (ctx->options.min_step > 0.0 && step == BK_STEP_OK) {
            double lo, hi;
            ctx->backend->last_step(isl->solver, &lo, &hi);
            if (hi - lo < ctx->options.min_step)
                return BK_FAIL(ctx->err, BK_ERR_SOLVER,
                               "the step size fell to %.3g s, below [solver] min_step = %g s, at t = %.17g s",
                               hi - lo, ctx->options.min_step, t_reached);
        }
        bk_island_arm(&isl->island, t_reached, isl->y);
        if (missed_stop(ctx, isl))
            rc = find_event(ctx, isl, t_reached, 0);
    }
    if (rc != BK_OK)
        return rc;
    if ((rc = bk_run_catalog_island_step(ctx, isl)) != BK_OK ||
        (rc = bk_run_ruptures_island_step(ctx, isl)) != BK_OK)
        return rc;
    bk_heap_set(&ctx->island_queue, id, island_key(isl));
    /* Every step, so that a wall-clock limit bites inside long segments. */
    return bk_run_report_progress(ctx, t_reached);
}

int bk_run_apply_event(run_ctx *ctx, double t, size_t i, bk_mode_event event)
{
    bk_scene *scene = &ctx->scene;
    double driver_pos = bk_driver_position(&ctx->model->driver, t);
    double force = bk_scene_applied_force(scene, i, driver_pos);
    bk_mode from = (bk_mode)scene->mode[i];
    bk_mode to = bk_mode_next(from, event, force, bk_scene_static_threshold(scene, i));
    scene->v[i] = 0.0;
    if (to != BK_MODE_STICK) {
        scene->t_switch[i] = t;
        scene->from_rest[i] = 1;
    }
    if (from == BK_MODE_STICK && to != BK_MODE_STICK)
        bk_run_leave_stuck(ctx, i, t);
    scene->mode[i] = (int8_t)to;
    if (from != BK_MODE_STICK && to == BK_MODE_STICK)
        bk_run_enter_stuck(ctx, i, t);
    if (to == from)
        return 0;
    int rc = bk_run_record_transition(ctx, t, i, from, to, force);
    return rc < 0 ? rc : 1;
}

/* Whether the pending event is only slip-rate threshold crossings of blocks that cannot
 * stick.  Such a crossing changes the catalog, not the ODE: the integration goes on through
 * it instead of restarting.  A restart would begin from the dense output at the crossing,
 * whose error (at loose tolerances, more than the slip rate's distance from the threshold a
 * moment later) a block with little mass sheds within m / damping, crossing back and forth:
 * spurious events of nanoseconds.  Carrying on, each crossing is found once. */
static int crossings_only(const run_ctx *ctx, const run_island *isl)
{
    const bk_scene *scene = &ctx->scene;
    size_t R = scene->roots_per_block;
    if (!isl->from_root || isl->hidden_block != SIZE_MAX)
        return 0;
    int any = 0;
    for (size_t k = 0; k < isl->island.len; ++k)
        for (size_t r = 0; r < R; ++r) {
            if (isl->found[R * k + r] == 0)
                continue;
            if (r != BK_ROOT_MAIN || scene->can_stick[bk_island_block(&isl->island, k)])
                return 0;
            any = 1;
        }
    return any;
}

int bk_run_island_event(run_ctx *ctx, size_t id)
{
    run_island *isl = ctx->islands[id];
    const bk_scene *scene = &ctx->scene;
    size_t R = scene->roots_per_block;
    double t = isl->t_event;
    const bk_island *island = &isl->island;
    int through = crossings_only(ctx, isl);
    bk_energy increments;
    int rc = bk_run_unpack_island(ctx, isl, t, 0, &increments);
    if (rc != BK_OK)
        return rc;
    /* The energy quadratures run on when the integration does. */
    if (!through)
        bk_energy_add(&ctx->closed, &increments);
    /* Every root but a threshold crossing restarts the island.  A minimum that hid no stop
     * disarms its root until the block decelerates again, so the restart does not begin on a
     * zero of it. */
    if (isl->hidden_block == SIZE_MAX)
        for (size_t k = 0; k < island->len; ++k)
            if (isl->found[R * k + BK_ROOT_EXTREMUM])
                ctx->scene.extremum_armed[bk_island_block(island, k)] = 0;
    /* After a rewind only the hidden stop happened at t; otherwise every root that fired at
     * the root's time is handled now, or its function would restart past its zero and be
     * lost. */
    int rewound = t < isl->t_reached;
    int changed = 0;
    for (size_t k = 0; k < island->len; ++k) {
        size_t i = bk_island_block(island, k);
        int fired = i == isl->hidden_block || (!rewound && isl->found[R * k + BK_ROOT_MAIN] != 0);
        if (!fired)
            continue;
        if (!scene->can_stick[i]) {
            if ((rc = bk_run_record_crossing(ctx, t, i, isl->found[R * k + BK_ROOT_MAIN] > 0)) != BK_OK ||
                (through && (rc = bk_run_ruptures_crossed(ctx, i, t)) != BK_OK))
                return rc;
            continue;
        }
        bk_mode_event event = bk_scene_stuck(scene, i) ? BK_EVENT_BREAKAWAY : BK_EVENT_STOP;
        rc = bk_run_apply_event(ctx, t, i, event);
        if (rc < 0)
            return rc;
        changed |= rc;
    }
    isl->pending = 0;
    if (through) {
        /* Nothing the integrator sees has changed: it carries on from where it is, past t. */
        isl->t_resume = t;
        bk_heap_set(&ctx->island_queue, id, isl->t_reached);
        return BK_OK;
    }
    if (changed && ctx->event_rows)
        ctx->t_row_due = t;
    if (!changed)
        return bk_run_start_island(ctx, id, t);
    return bk_run_repartition(ctx, island->blocks, island->len, t, id);
}

int bk_run_quiet_failures(run_ctx *ctx, double t)
{
    bk_scene *scene = &ctx->scene;
    const bk_model *model = ctx->model;
    /* Every block whose breakaway falls on this instant (to rounding) slips now. */
    double limit = t + SIMULTANEOUS_EPS * fabs(t);
    size_t count = 0;
    while (!bk_heap_empty(&ctx->quiet) && bk_heap_top_key(&ctx->quiet) <= limit)
        ctx->batch[count++] = bk_heap_pop(&ctx->quiet);
    qsort(ctx->batch, count, sizeof *ctx->batch, bk_compare_blocks);
    double driver_pos = bk_driver_position(&model->driver, t);
    /* The force crosses the threshold the way the driver pulls; passing that direction
     * instead of the force itself is immune to rounding at the threshold.  A resting driver
     * (a hold) pulls nowhere: a threshold aging below the force gives way to the force. */
    double speed = bk_driver_velocity(&model->driver, t);
    for (size_t k = 0; k < count; ++k) {
        size_t i = ctx->batch[k];
        bk_scene_age(scene, i, t);
        double force = bk_scene_applied_force(scene, i, driver_pos);
        double pull = speed > 0.0 ? 1.0 : speed < 0.0 ? -1.0 : force >= 0.0 ? 1.0 : -1.0;
        bk_mode from = (bk_mode)scene->mode[i];
        bk_mode to = bk_mode_next(from, BK_EVENT_BREAKAWAY, pull, 0.0);
        bk_run_leave_stuck(ctx, i, t);
        scene->mode[i] = (int8_t)to;
        scene->t_switch[i] = t;
        scene->from_rest[i] = 1;
        int rc = bk_run_record_transition(ctx, t, i, from, to, force);
        if (rc != BK_OK)
            return rc;
    }
    ctx->stats->stuck_jumps++;
    if (count > 0 && ctx->event_rows)
        ctx->t_row_due = t;
    return count > 0 ? bk_run_repartition(ctx, ctx->batch, count, t, BK_NO_ISLAND) : BK_OK;
}
