/* The run loop, shared by every solver back-end.
 *
 *   t = 0: resolve initial modes, emit the first row.
 *   repeat until t_end:
 *     every block stuck and no friction state: nothing to integrate; find the next breakaway
 *       in closed form (the applied forces are linear in the driver position) and jump;
 *     otherwise: restart the back-end on the compact ODE of the slipping blocks (or the
 *       full-layout DAE, for a back-end that wants it), step, emit samples by dense output,
 *       and at a root let the mode machine decide.
 *
 * A slip-rate minimum with s v < 0 means a stop hidden inside one step (velocity dipped
 * through zero and back): the stop is located on the step's interpolant and the run
 * rewinds to it.  Nothing else can have happened in between, because the back-end reports
 * the earliest root of the step. */
#include "bksim/run.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include "bksim/checkpoint.h"
#include "bksim/solver.h"
#include "method_choice.h"
#include "prescribed.h"
#include "scene.h"

#define PI 3.14159265358979323846

typedef struct run_ctx {
    const bk_config *config;
    const bk_model *model;
    const bk_sink *sink;
    bk_error *err;
    bk_run_stats *stats;
    bk_progress_fn progress;
    void *progress_user;

    bk_scene scene;
    const bk_solver_backend *backend;
    void *solver;
    bk_solver_options options; /* with auto values resolved */
    bk_ode_problem problem;
    double atol_x, atol_v, atol_state, atol_energy;
    double *y, *y_probe, *atol;
    int *found;
    double *friction, *cof;

    /* output schedule */
    double t_end;
    double interval;
    long next_sample;     /* index k of the next sample time k * interval */
    double t_last_row;
    long steps_since_row;
    int event_rows;

    /* chattering guard */
    double instant_window;
    double *last_transition;
    long *instant_count;

    double elastic0, kinetic0;
    double wall_start;    /* s, monotonic clock at the start */
    double cpu0;          /* clock() at the start */

    /* checkpoints: forced restarts at multiples of the interval */
    double checkpoint_interval;
    long next_checkpoint; /* index k of the next checkpoint time k * interval */
    bk_run_stats base;    /* counters of the run this one resumed, if any */
} run_ctx;

/* Next checkpoint time (+inf without checkpoints); always < t_end or +inf. */
static double checkpoint_time(const run_ctx *ctx)
{
    if (ctx->checkpoint_interval <= 0.0)
        return INFINITY;
    double t = (double)ctx->next_checkpoint * ctx->checkpoint_interval;
    return t < ctx->t_end ? t : INFINITY;
}

/* --- output ---------------------------------------------------------------------------- */

static double sample_time(const run_ctx *ctx, long k)
{
    if (ctx->interval <= 0.0)
        return ctx->t_end;
    double t = (double)k * ctx->interval;
    return t >= ctx->t_end - 1e-9 * ctx->interval ? ctx->t_end : t;
}

static double wall_seconds(void);
static int report_progress(run_ctx *ctx, double t);

/* Emit one row from the scene's unpacked state at time t. */
static int emit_row(run_ctx *ctx, double t, int is_event)
{
    const bk_model *model = ctx->model;
    bk_scene *scene = &ctx->scene;
    double driver_pos = bk_driver_position(&model->driver, t);
    for (size_t i = 0; i < scene->n; ++i) {
        ctx->friction[i] = bk_scene_friction(scene, i, driver_pos);
        ctx->cof[i] = ctx->friction[i] / scene->normal[i];
    }
    bk_sample sample = {
        .t = t,
        .driver = driver_pos,
        .n_blocks = scene->n,
        .x = scene->x,
        .v = scene->v,
        .friction = ctx->friction,
        .cof = ctx->cof,
        .mode = scene->mode,
        .friction_state = model->n_friction_state ? scene->state : NULL,
        .kinetic_energy = bk_model_kinetic_energy(model, scene->v),
        .elastic_energy = bk_model_elastic_energy(model, scene->x, driver_pos),
        .work_driver = scene->work,
        .dissipation = scene->dissipation,
        .is_event = is_event,
    };
    /* Rows can come without steps (all stuck, or dense sampling): a stop request and the
     * wall clock are checked here too, before the row counts as written. */
    int rc = report_progress(ctx, t);
    if (rc != BK_OK)
        return rc;
    ctx->t_last_row = t;
    ctx->steps_since_row = 0;
    ctx->stats->rows++;
    if (ctx->sink && ctx->sink->sample) {
        rc = ctx->sink->sample(ctx->sink->self, &sample, ctx->err);
        if (rc != BK_OK)
            return rc < 0 ? rc : BK_ERR_SINK;
    }
    return BK_OK;
}

/* Emit the samples due before t_limit (at or before it when inclusive) from the current
 * integrator step's dense output.  Leaves the scene unpacked at the last sample. */
static int emit_interpolated(run_ctx *ctx, double t_limit, int inclusive)
{
    for (;;) {
        double ts = sample_time(ctx, ctx->next_sample);
        if (ts > ctx->t_end || (inclusive ? ts > t_limit : ts >= t_limit) ||
            ctx->next_sample < 0)
            return BK_OK;
        int rc = ctx->backend->interpolate(ctx->solver, ts, ctx->y_probe, ctx->err);
        if (rc != BK_OK)
            return rc;
        bk_scene_unpack(&ctx->scene, ts, ctx->y_probe);
        if ((rc = emit_row(ctx, ts, 0)) != BK_OK)
            return rc;
        ctx->next_sample = ts >= ctx->t_end ? -1 : ctx->next_sample + 1;
    }
}

/* Skip a sample that falls exactly on an event row already written. */
static void skip_sample_at(run_ctx *ctx, double t)
{
    if (ctx->next_sample >= 0 && sample_time(ctx, ctx->next_sample) == t)
        ctx->next_sample = t >= ctx->t_end ? -1 : ctx->next_sample + 1;
}

/* --- transitions ----------------------------------------------------------------------- */

static int record_transition(run_ctx *ctx, double t, size_t i, bk_mode from, bk_mode to,
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
    if (!ctx->config->output.transitions || !ctx->sink || !ctx->sink->transition)
        return BK_OK;
    bk_transition tr = {
        .t = t,
        .block = (int32_t)i,
        .from = (int8_t)from,
        .to = (int8_t)to,
        .x = scene->x[i],
        .v = scene->v[i],
        .force = applied_force,
    };
    int rc = ctx->sink->transition(ctx->sink->self, &tr, ctx->err);
    return rc == BK_OK ? BK_OK : (rc < 0 ? rc : BK_ERR_SINK);
}

/* Apply the machine to block i at time t (scene unpacked there).  Returns 1 when its mode
 * changed, 0 when not, < 0 on failure. */
static int apply_event(run_ctx *ctx, double t, size_t i, bk_mode_event event)
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
    scene->mode[i] = (int8_t)to;
    if (to == from)
        return 0;
    int rc = record_transition(ctx, t, i, from, to, force);
    return rc < 0 ? rc : 1;
}

/* --- checkpoints ----------------------------------------------------------------------- */

static double wall_seconds(void);

/* Counters so far, the resumed run's included. */
static void collect_stats(const run_ctx *ctx, bk_run_stats *stats, double cpu0)
{
    const bk_run_stats *base = &ctx->base;
    if (ctx->solver) {
        bk_solver_counters c;
        ctx->backend->counters(ctx->solver, &c);
        stats->steps = base->steps + c.steps;
        stats->rhs_evals = base->rhs_evals + c.rhs_evals;
        stats->root_evals = base->root_evals + c.root_evals;
        stats->err_test_fails = base->err_test_fails + c.err_test_fails;
        stats->nonlin_iters = base->nonlin_iters + c.nonlin_iters;
    }
    stats->t_reached = ctx->t_last_row;
    stats->wall_time = base->wall_time + (wall_seconds() - ctx->wall_start);
    stats->cpu_time = base->cpu_time + (double)(clock() - (clock_t)cpu0) / CLOCKS_PER_SEC;
}

/* Record the state at t (the scene unpacked there) and advance to the next checkpoint. */
static int emit_checkpoint(run_ctx *ctx, double t)
{
    ctx->next_checkpoint++;
    if (!ctx->sink || !ctx->sink->checkpoint)
        return BK_OK;
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
        .work_driver = scene->work,
        .dissipation = scene->dissipation,
        .elastic_initial = ctx->elastic0,
        .kinetic_initial = ctx->kinetic0,
        .t_last_row = ctx->t_last_row,
        .steps_since_row = ctx->steps_since_row,
    };
    cp.stats = *ctx->stats;
    collect_stats(ctx, &cp.stats, ctx->cpu0);
    int rc = ctx->sink->checkpoint(ctx->sink->self, &cp, ctx->err);
    return rc == BK_OK ? BK_OK : (rc < 0 ? rc : BK_ERR_SINK);
}

/* --- integration ----------------------------------------------------------------------- */

typedef struct stop_probe {
    run_ctx *ctx;
    size_t block;
    int status;
} stop_probe;

/* The stop root function of a slipping block on the last step's interpolant. */
static double stop_function(double t, void *user)
{
    stop_probe *probe = user;
    run_ctx *ctx = probe->ctx;
    bk_scene *scene = &ctx->scene;
    size_t i = probe->block;
    int rc = ctx->backend->interpolate(ctx->solver, t, ctx->y_probe, ctx->err);
    if (rc != BK_OK) {
        probe->status = rc;
        return 0.0;
    }
    double slip_rate = (double)scene->mode[i] * ctx->y_probe[scene->slot[i] + 1];
    double since = t - scene->t_switch[i];
    if (scene->from_rest[i] && since <= 0.0)
        return 1.0; /* the limit s a > 0 at the start of a slip from rest */
    return scene->from_rest[i] ? slip_rate / since : slip_rate;
}

/* Locate the stop of block i hidden inside the last step before t_root. */
static int locate_hidden_stop(run_ctx *ctx, size_t i, double t_root, double *t_stop)
{
    double lo, hi;
    ctx->backend->last_step(ctx->solver, &lo, &hi);
    if (lo < ctx->scene.t_ref)
        lo = ctx->scene.t_ref;
    stop_probe probe = {ctx, i, BK_OK};
    gsl_function fn = {stop_function, &probe};
    double f_lo = stop_function(lo, &probe), f_hi = stop_function(t_root, &probe);
    if (probe.status != BK_OK)
        return probe.status;
    if (f_hi >= 0.0 || f_lo <= 0.0) {
        *t_stop = f_hi >= 0.0 ? t_root : lo;
        return BK_OK;
    }
    gsl_root_fsolver *solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!solver)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory locating a stop");
    gsl_root_fsolver_set(solver, &fn, lo, t_root);
    for (int iter = 0; iter < 200; ++iter) {
        if (gsl_root_fsolver_iterate(solver) != GSL_SUCCESS)
            break;
        double a = gsl_root_fsolver_x_lower(solver), b = gsl_root_fsolver_x_upper(solver);
        if (gsl_root_test_interval(a, b, 0.0, 4.0 * DBL_EPSILON) == GSL_SUCCESS)
            break;
    }
    /* The upper end is past the zero: the state there has s v <= 0, as at a found root. */
    *t_stop = gsl_root_fsolver_x_upper(solver);
    gsl_root_fsolver_free(solver);
    return probe.status;
}

/* Handle a root reported at t_root with state y (from_root), or a step end where a
 * slipping block's velocity is found past zero although no root fired (a stop the root
 * functions could not see, e.g. one masked at a restart).  Emits the samples before the
 * event, the transitions and the event row; sets *t_event.  Returns 0, or < 0 on failure;
 * the caller restarts the integrator at *t_event. */
static int handle_root(run_ctx *ctx, double t_root, int from_root, double *t_event)
{
    bk_scene *scene = &ctx->scene;
    size_t n = scene->n, R = scene->roots_per_block;
    if (from_root) {
        int rc = ctx->backend->root_info(ctx->solver, ctx->found);
        if (rc != BK_OK)
            return BK_FAIL(ctx->err, BK_ERR_SOLVER, "cannot read root information at t = %.17g s", t_root);
    } else {
        memset(ctx->found, 0, n * R * sizeof *ctx->found);
    }
    bk_scene_unpack(scene, t_root, ctx->y);
    int rc;

    /* A slip-rate minimum below zero, or a velocity past zero at a step end: the stop hid
     * inside the step. */
    double t_hidden = t_root;
    size_t hidden_block = SIZE_MAX;
    for (size_t i = 0; i < n; ++i) {
        if (bk_scene_stuck(scene, i) || !scene->can_stick[i] || ctx->found[R * i + BK_ROOT_MAIN])
            continue;
        if (from_root && !ctx->found[R * i + BK_ROOT_EXTREMUM])
            continue;
        double slip_rate = (double)scene->mode[i] * scene->v[i];
        if (from_root ? slip_rate > 0.0 : slip_rate >= 0.0)
            continue;
        double t_stop = t_root;
        if ((rc = locate_hidden_stop(ctx, i, t_root, &t_stop)) != BK_OK)
            return rc;
        if (t_stop < t_hidden || hidden_block == SIZE_MAX) {
            t_hidden = t_stop;
            hidden_block = i;
        }
    }

    double t = hidden_block != SIZE_MAX ? t_hidden : t_root;
    /* Every root restarts the integrator.  A minimum that hid no stop disarms its root until
     * the block decelerates again, so the restart does not begin on a zero of it. */
    if (hidden_block == SIZE_MAX)
        for (size_t i = 0; i < n; ++i)
            if (ctx->found[R * i + BK_ROOT_EXTREMUM])
                scene->extremum_armed[i] = 0;

    /* Samples strictly before the event, then the state at the event itself. */
    if ((rc = emit_interpolated(ctx, t, 0)) != BK_OK)
        return rc;
    if (t != t_root) {
        if ((rc = ctx->backend->interpolate(ctx->solver, t, ctx->y_probe, ctx->err)) != BK_OK)
            return rc;
        bk_scene_unpack(scene, t, ctx->y_probe);
    } else {
        bk_scene_unpack(scene, t, ctx->y);
    }

    /* After a rewind only the hidden stop happened at t; otherwise every root that fired
     * at t_root is handled now, or its function would restart past its zero and be lost. */
    int rewound = t < t_root;
    int changed = 0;
    for (size_t i = 0; i < n; ++i) {
        int fired = i == hidden_block || (!rewound && ctx->found[R * i + BK_ROOT_MAIN] != 0);
        if (!fired)
            continue;
        bk_mode_event event = bk_scene_stuck(scene, i) ? BK_EVENT_BREAKAWAY : BK_EVENT_STOP;
        rc = apply_event(ctx, t, i, event);
        if (rc < 0)
            return rc;
        changed |= rc;
    }
    if (changed && ctx->event_rows) {
        if ((rc = emit_row(ctx, t, 1)) != BK_OK)
            return rc;
        skip_sample_at(ctx, t);
    }
    *t_event = t;
    return BK_OK;
}

/* A slipping block whose velocity is past zero at a step end without a root. */
static int missed_stop(const run_ctx *ctx)
{
    const bk_scene *scene = &ctx->scene;
    for (size_t k = 0; k < scene->n_active; ++k) {
        size_t i = scene->active[k];
        if (scene->can_stick[i] && (double)scene->mode[i] * ctx->y[scene->slot[i] + 1] < 0.0)
            return 1;
    }
    return 0;
}

static int check_finite(run_ctx *ctx, double t)
{
    for (size_t k = 0; k < ctx->scene.n_y; ++k)
        if (!isfinite(ctx->y[k]))
            return BK_FAIL(ctx->err, BK_ERR_NUMERIC,
                           "non-finite value in the solution at t = %.17g s (component %zu)", t, k);
    return BK_OK;
}

static double wall_seconds(void);

static int report_progress(run_ctx *ctx, double t)
{
    if (ctx->progress && ctx->progress(ctx->progress_user, t, ctx->t_end) != 0)
        return BK_FAIL(ctx->err, BK_ERR_INTERRUPTED, "run interrupted at t = %.17g s", t);
    double limit = ctx->config->wall_time_limit;
    if (limit > 0.0 && wall_seconds() - ctx->wall_start > limit)
        return BK_FAIL(ctx->err, BK_ERR_INTERRUPTED,
                       "[run] wall_time_limit = %g s reached at t = %.17g s of %g s", limit, t, ctx->t_end);
    return BK_OK;
}

/* Integrate from *t until the next event that changes the layout, or t_end. */
static int integrate(run_ctx *ctx, double *t)
{
    bk_scene *scene = &ctx->scene;
    bk_scene_restart(scene, *t, ctx->y);
    bk_scene_tolerances(scene, ctx->atol_x, ctx->atol_v, ctx->atol_state, ctx->atol_energy, ctx->atol);
    ctx->problem.half_bandwidth = scene->half_bandwidth;
    /* Pairs lead the layout only when no friction state is interleaved; the full layout's
     * stuck pairs are no oscillators, so it declares no structure. */
    ctx->problem.n_pairs = ctx->model->n_friction_state == 0 && !scene->full_layout ? scene->n_active : 0;
    ctx->problem.pair_mass = scene->active_mass;
    ctx->problem.affine = scene->affine && !scene->full_layout;
    double t_checkpoint = checkpoint_time(ctx);
    double t_stop = t_checkpoint < ctx->t_end ? t_checkpoint : ctx->t_end;
    int rc = ctx->backend->start(ctx->solver, &ctx->problem, *t, ctx->y, ctx->atol, scene->n_y,
                                 t_stop, ctx->err);
    if (rc != BK_OK)
        return rc;
    ctx->stats->integrator_starts++;
    for (;;) {
        double t_reached;
        int step = ctx->backend->step(ctx->solver, &t_reached, ctx->y, ctx->err);
        if (step < 0)
            return step;
        if ((rc = check_finite(ctx, t_reached)) != BK_OK)
            return rc;
        if (++ctx->steps_since_row > ctx->options.max_steps)
            return BK_FAIL(ctx->err, BK_ERR_MAX_STEPS,
                           "more than %ld solver steps since the last output row (t = %.17g s, "
                           "now at t = %.17g s); raise [solver] max_steps or loosen rtol",
                           ctx->options.max_steps, ctx->t_last_row, t_reached);
        if (step == BK_STEP_ROOT) {
            double t_event = t_reached;
            if ((rc = handle_root(ctx, t_reached, 1, &t_event)) != BK_OK)
                return rc;
            *t = t_event;
            return report_progress(ctx, *t);
        }
        if (ctx->options.min_step > 0.0 && step == BK_STEP_OK) {
            double lo, hi;
            ctx->backend->last_step(ctx->solver, &lo, &hi);
            if (hi - lo < ctx->options.min_step)
                return BK_FAIL(ctx->err, BK_ERR_SOLVER,
                               "the step size fell to %.3g s, below [solver] min_step = %g s, at t = %.17g s",
                               hi - lo, ctx->options.min_step, t_reached);
        }
        bk_scene_arm(scene, t_reached, ctx->y);
        if (missed_stop(ctx)) {
            double t_event = t_reached;
            if ((rc = handle_root(ctx, t_reached, 0, &t_event)) != BK_OK)
                return rc;
            *t = t_event;
            return report_progress(ctx, *t);
        }
        if ((rc = emit_interpolated(ctx, t_reached, 1)) != BK_OK)
            return rc;
        if (step == BK_STEP_STOP) {
            bk_scene_unpack(scene, t_reached, ctx->y);
            *t = t_stop;
            /* A checkpoint: the main loop restarts here, as a resumed run will. */
            return t_stop < ctx->t_end ? emit_checkpoint(ctx, t_stop) : BK_OK;
        }
        if ((rc = report_progress(ctx, t_reached)) != BK_OK)
            return rc; /* every step, so that a wall-clock limit bites inside long segments */
    }
}

/* --- all blocks stuck ------------------------------------------------------------------ */

/* Driver work over a stuck interval: the antiderivative of k ramp(D - x) in D. */
static double stuck_work(const run_ctx *ctx, double d0, double d1)
{
    const bk_model *model = ctx->model;
    double work = 0.0;
    for (size_t i = 0; i < model->n_blocks; ++i) {
        double e0 = d0 - ctx->scene.x[i], e1 = d1 - ctx->scene.x[i];
        if (model->spring == BK_SPRING_TENSION_ONLY) {
            e0 = e0 > 0.0 ? e0 : 0.0;
            e1 = e1 > 0.0 ? e1 : 0.0;
        }
        work += 0.5 * model->blocks[i].driver_stiffness * (e1 - e0) * (e1 + e0);
    }
    return work;
}

/* Time block i breaks away if every block stays stuck, from the applied force's linear
 * dependence on the driver position; +inf if never. */
static double breakaway_time(const run_ctx *ctx, size_t i, double t)
{
    const bk_model *model = ctx->model;
    const bk_scene *scene = &ctx->scene;
    double k = model->blocks[i].driver_stiffness;
    double velocity = bk_driver_velocity(&model->driver, t);
    if (k == 0.0 || velocity == 0.0)
        return INFINITY;
    double coupling = bk_model_coupling_force(model, i, scene->x);
    double threshold = bk_scene_static_threshold(scene, i);
    /* The driver spring force rises with D when the driver advances, falls when it retreats;
     * a tension-only spring can only pull, so a retreating driver never breaks it away
     * unless the coupling alone does. */
    double target_force = velocity > 0.0 ? threshold - coupling : -threshold - coupling;
    if (velocity < 0.0 && model->spring == BK_SPRING_TENSION_ONLY && target_force < 0.0)
        return INFINITY;
    double target_position = scene->x[i] + target_force / k;
    double here = bk_driver_position(&model->driver, t);
    if ((target_position - here) * velocity <= 0.0)
        return t;
    return bk_driver_time_at(&model->driver, t, target_position);
}

static int jump(run_ctx *ctx, double *t)
{
    bk_scene *scene = &ctx->scene;
    const bk_model *model = ctx->model;
    double t0 = *t;
    double t_fail = INFINITY;
    for (size_t i = 0; i < scene->n; ++i) {
        double ti = breakaway_time(ctx, i, t0);
        if (ti < t_fail)
            t_fail = ti;
    }
    double t_checkpoint = checkpoint_time(ctx);
    double t_stop = t_checkpoint < ctx->t_end ? t_checkpoint : ctx->t_end;
    double t_next = t_fail < t_stop ? t_fail : t_stop;
    double d0 = bk_driver_position(&model->driver, t0);
    double work0 = scene->work;
    int rc;
    /* Samples while everything holds still; only the driver and its work change. */
    for (;;) {
        double ts = sample_time(ctx, ctx->next_sample);
        if (ctx->next_sample < 0 || ts > t_next || (ts == t_next && t_fail <= t_stop && ctx->event_rows))
            break;
        scene->work = work0 + stuck_work(ctx, d0, bk_driver_position(&model->driver, ts));
        if ((rc = emit_row(ctx, ts, 0)) != BK_OK)
            return rc;
        ctx->next_sample = ts >= ctx->t_end ? -1 : ctx->next_sample + 1;
    }
    scene->work = work0 + stuck_work(ctx, d0, bk_driver_position(&model->driver, t_next));
    ctx->stats->stuck_jumps++;
    *t = t_next;
    if (t_fail > t_stop)
        return t_stop < ctx->t_end ? emit_checkpoint(ctx, t_stop) : BK_OK;
    /* Every block whose breakaway falls on this instant (to rounding) slips now. */
    double tolerance = 8.0 * DBL_EPSILON * fabs(t_fail);
    int changed = 0;
    for (size_t i = 0; i < scene->n; ++i) {
        if (breakaway_time(ctx, i, t0) > t_fail + tolerance)
            continue;
        double force = bk_scene_applied_force(scene, i, bk_driver_position(&model->driver, t_fail));
        /* The force crosses the threshold the way the driver pulls; passing that direction
         * instead of the force itself is immune to rounding at the threshold. */
        double pull = bk_driver_velocity(&model->driver, t_fail) > 0.0 ? 1.0 : -1.0;
        bk_mode from = (bk_mode)scene->mode[i];
        bk_mode to = bk_mode_next(from, BK_EVENT_BREAKAWAY, pull, 0.0);
        scene->mode[i] = (int8_t)to;
        scene->t_switch[i] = t_fail;
        scene->from_rest[i] = 1;
        if ((rc = record_transition(ctx, t_fail, i, from, to, force)) != BK_OK)
            return rc;
        changed = 1;
    }
    if (changed && ctx->event_rows) {
        if ((rc = emit_row(ctx, t_fail, 1)) != BK_OK)
            return rc;
        skip_sample_at(ctx, t_fail);
    }
    return report_progress(ctx, *t);
}

/* --- set-up ---------------------------------------------------------------------------- */

static int needs_integration(const bk_scene *scene)
{
    if (scene->model->n_friction_state > 0)
        return 1;
    for (size_t i = 0; i < scene->n; ++i)
        if (scene->mode[i] != BK_MODE_STICK)
            return 1;
    return 0;
}

/* Fill the auto tolerances, step limit and chattering window from the model's scales. */
static void resolve_scales(run_ctx *ctx)
{
    const bk_model *model = ctx->model;
    bk_solver_options *opt = &ctx->options;
    double omega = bk_model_max_angular_frequency(model);
    double period = omega > 0.0 ? 2.0 * PI / omega : INFINITY;
    double length = 0.0, force = 0.0;
    for (size_t i = 0; i < model->n_blocks; ++i) {
        double stiffness = model->blocks[i].driver_stiffness +
                           bk_model_coupling_count(model, i) * model->coupling_stiffness;
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
    if (isnan(opt->max_step))
        opt->max_step = isfinite(period) ? period / 8.0 : 0.0;
    ctx->instant_window = !isnan(opt->instant_window) ? opt->instant_window
                          : isfinite(period)           ? 1e-6 * period
                                                       : 1e-12 * ctx->t_end;
}

static void free_ctx(run_ctx *ctx)
{
    if (ctx->solver)
        ctx->backend->destroy(ctx->solver);
    bk_scene_free(&ctx->scene);
    free(ctx->y);
    free(ctx->y_probe);
    free(ctx->atol);
    free(ctx->found);
    free(ctx->friction);
    free(ctx->cof);
    free(ctx->last_transition);
    free(ctx->instant_count);
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
        int rc = apply_event(ctx, 0.0, i, BK_EVENT_STOP);
        if (rc < 0)
            return rc;
        *any_transition |= rc;
    }
    return BK_OK;
}

static double wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The state of a checkpoint, back into the scene (x_ref = x: the run restarts there). */
static int resume(run_ctx *ctx, const bk_checkpoint *cp)
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
    scene->work = cp->work_driver;
    scene->dissipation = cp->dissipation;
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
    double wall0 = wall_seconds();
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
    size_t n = ctx.model->n_blocks;
    size_t max_y = 2 * n + ctx.model->n_friction_state + 2;
    ctx.y = calloc(max_y, sizeof *ctx.y);
    ctx.y_probe = calloc(max_y, sizeof *ctx.y_probe);
    ctx.atol = calloc(max_y, sizeof *ctx.atol);
    ctx.found = calloc(n * ctx.scene.roots_per_block, sizeof *ctx.found);
    ctx.friction = calloc(n, sizeof *ctx.friction);
    ctx.cof = calloc(n, sizeof *ctx.cof);
    ctx.last_transition = malloc(n * sizeof *ctx.last_transition);
    ctx.instant_count = calloc(n, sizeof *ctx.instant_count);
    int rc = BK_OK;
    if (!ctx.y || !ctx.y_probe || !ctx.atol || !ctx.found || !ctx.friction || !ctx.cof ||
        !ctx.last_transition || !ctx.instant_count) {
        rc = BK_FAIL(err, BK_ERR_NOMEM, "out of memory for %zu blocks", n);
        goto done;
    }
    for (size_t i = 0; i < n; ++i)
        ctx.last_transition[i] = -INFINITY;
    /* Scales come from the initial state in a resumed run too, so both runs use the same. */
    resolve_scales(&ctx);
    ctx.problem = (bk_ode_problem){
        .user = &ctx.scene,
        .rhs = bk_scene_rhs,
        .jacobian = bk_scene_jacobian,
        .rhs_split = bk_scene_rhs_split,
        .jacobian_implicit = bk_scene_jacobian_implicit,
        .roots = bk_scene_roots,
        .n_roots = n * ctx.scene.roots_per_block,
        .root_direction = ctx.scene.root_direction,
        .differential_id = ctx.backend->wants_full_layout ? ctx.scene.differential_id : NULL,
    };
    ctx.scene.full_layout = ctx.backend->wants_full_layout;
    if ((rc = ctx.backend->create(&ctx.solver, &ctx.options, err)) != BK_OK) {
        ctx.solver = NULL;
        goto done;
    }

    double t = 0.0;
    if (from) {
        if ((rc = resume(&ctx, from)) != BK_OK)
            goto done;
        t = from->t;
    } else {
        int moved;
        if ((rc = initial_modes(&ctx, &moved)) != BK_OK)
            goto done;
        double driver0 = bk_driver_position(&ctx.model->driver, 0.0);
        ctx.elastic0 = bk_model_elastic_energy(ctx.model, ctx.scene.x, driver0);
        ctx.kinetic0 = bk_model_kinetic_energy(ctx.model, ctx.scene.v);
        if ((rc = emit_row(&ctx, 0.0, moved)) != BK_OK)
            goto done;
        ctx.next_sample = 1;
    }
    while (t < ctx.t_end) {
        rc = needs_integration(&ctx.scene) ? integrate(&ctx, &t) : jump(&ctx, &t);
        if (rc != BK_OK)
            break;
    }

done:
    collect_stats(&ctx, ctx.stats, (double)cpu0);
    if (ctx.scene.x) {
        bk_run_stats *st = ctx.stats;
        double d = bk_driver_position(&ctx.model->driver, ctx.t_last_row);
        st->work_driver = ctx.scene.work;
        st->dissipation = ctx.scene.dissipation;
        st->elastic_change = bk_model_elastic_energy(ctx.model, ctx.scene.x, d) - ctx.elastic0;
        st->kinetic_change = bk_model_kinetic_energy(ctx.model, ctx.scene.v) - ctx.kinetic0;
        double scale = fmax(fmax(fabs(st->work_driver), fabs(st->dissipation)),
                            fmax(fabs(st->elastic_change), fabs(st->kinetic_change)));
        double residual = st->work_driver - st->elastic_change - st->kinetic_change - st->dissipation;
        st->energy_residual = scale > 0.0 ? residual / scale : 0.0;
        if (rc == BK_OK && !isfinite(st->energy_residual))
            rc = BK_FAIL(err, BK_ERR_NUMERIC,
                         "the energy audit overflowed at t = %.17g s (driver work %g J, elastic change %g J, "
                         "kinetic change %g J, dissipation %g J): the motion's scale is beyond double "
                         "precision",
                         ctx.t_last_row, st->work_driver, st->elastic_change, st->kinetic_change,
                         st->dissipation);
    }
    free_ctx(&ctx);
    return rc;
}
