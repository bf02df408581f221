/* The islands and quiet blocks of the partition (scene.h; run_partition.c builds it), and
 * what happens to them: an island steps with its own integrator and finds its next event;
 * at an event only that island (and a neighbour it may merge with) is rebuilt; a quiet
 * block breaks away at a time known in closed form (run_quiet.c), kept in a priority queue.
 * Nothing here loops over the chain except bk_run_unpack_all (output rows).
 *
 * Why the partition is safe: a quiet block's neighbours are stuck, so its applied force is
 * affine in the driver's position until one of them moves, which only happens through an
 * event that rebuilds the partition around it (and recomputes its failure time).  An island
 * depends on blocks outside it only through stuck ones, so islands integrated to different
 * times never see each other: the scheduler (run.c) always handles the earliest pending
 * event first, and every island's last step then contains that time, so its state there is
 * at hand (dense output) when a merge needs it. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_roots.h>

#include "capacity.h"
#include "run_impl.h"

/* Quiet blocks whose failure times agree to this many ulps fail at one instant (a uniform
 * chain's blocks all do). */
#define SIMULTANEOUS_EPS (8.0 * DBL_EPSILON)

/* Idle instances searched for one that last served a problem of the same size: a back-end
 * reuses its objects when the size repeats (allocating anew at every restart dominated on
 * long chains). */
#define IDLE_MATCH_SPAN 32
/* Unknowns above which an instance is destroyed when its island dissolves: making one for
 * a large island costs little next to restarting it, and kept ones would each hold the
 * largest island they ever served. */
#define POOL_LARGEST_Y 64

/* ---------------------------------------------------------------- bookkeeping --- */

int bk_run_islands_init(run_ctx *ctx)
{
    size_t n = ctx->scene.n;
    if (bk_heap_init(&ctx->quiet, n) != 0 || bk_heap_init(&ctx->island_queue, 16) != 0)
        return -1;
    /* Idle instances together hold no more than one instance for the whole chain. */
    ctx->idle_budget = bk_island_max_y(&ctx->scene, n);
    if (ctx->idle_budget < 16 * POOL_LARGEST_Y)
        ctx->idle_budget = 16 * POOL_LARGEST_Y;
    ctx->batch = malloc(n * sizeof *ctx->batch);
    ctx->brent = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    return ctx->batch && ctx->brent && bk_run_partition_init(ctx) == 0 ? 0 : -1;
}

void bk_run_islands_free(run_ctx *ctx)
{
    for (size_t id = 0; id < ctx->islands_used; ++id) {
        run_island *isl = ctx->islands[id];
        if (isl->solver)
            ctx->backend->destroy(isl->solver);
        bk_island_free(&isl->island);
        free(isl->y);
        free(isl->found);
        free(isl);
    }
    for (size_t k = 0; k < ctx->n_idle; ++k)
        ctx->backend->destroy(ctx->idle[k]);
    free(ctx->idle);
    free(ctx->idle_len);
    free(ctx->idle_peak);
    free(ctx->islands);
    free(ctx->free_ids);
    free(ctx->batch);
    bk_run_partition_free(ctx);
    if (ctx->brent)
        gsl_root_fsolver_free(ctx->brent);
    bk_heap_free(&ctx->quiet);
    bk_heap_free(&ctx->island_queue);
}

void bk_run_solver_counters(const run_ctx *ctx, bk_solver_counters *total)
{
    *total = ctx->retired;
    bk_solver_counters c;
    for (size_t id = 0; id < ctx->islands_used; ++id)
        if (ctx->islands[id]->solver) {
            ctx->backend->counters(ctx->islands[id]->solver, &c);
            bk_solver_counters_add(total, &c);
        }
    for (size_t k = 0; k < ctx->n_idle; ++k) {
        ctx->backend->counters(ctx->idle[k], &c);
        bk_solver_counters_add(total, &c);
    }
}

static double island_key(const run_island *isl)
{
    return isl->pending ? isl->t_event : isl->t_reached;
}

/* A back-end instance for a problem of n_y unknowns: an idle one, else a new one. */
static int take_solver(run_ctx *ctx, size_t n_y, run_island *isl)
{
    if (ctx->n_idle > 0) {
        size_t pick = ctx->n_idle - 1;
        for (size_t k = 0; k < IDLE_MATCH_SPAN && k < ctx->n_idle; ++k)
            if (ctx->idle_len[ctx->n_idle - 1 - k] == n_y) {
                pick = ctx->n_idle - 1 - k;
                break;
            }
        isl->solver = ctx->idle[pick];
        isl->solver_peak = ctx->idle_peak[pick];
        ctx->idle_held -= ctx->idle_peak[pick];
        size_t last = --ctx->n_idle;
        ctx->idle[pick] = ctx->idle[last];
        ctx->idle_len[pick] = ctx->idle_len[last];
        ctx->idle_peak[pick] = ctx->idle_peak[last];
        return BK_OK;
    }
    isl->solver_peak = 0;
    return ctx->backend->create(&isl->solver, &ctx->options, ctx->err);
}

static int grow_idle(run_ctx *ctx)
{
    size_t cap = ctx->idle_capacity ? 2 * ctx->idle_capacity : 16;
    void **idle = realloc(ctx->idle, cap * sizeof *idle);
    if (!idle)
        return -1;
    ctx->idle = idle;
    size_t *len = realloc(ctx->idle_len, cap * sizeof *len);
    if (!len)
        return -1;
    ctx->idle_len = len;
    size_t *peak = realloc(ctx->idle_peak, cap * sizeof *peak);
    if (!peak)
        return -1;
    ctx->idle_peak = peak;
    ctx->idle_capacity = cap;
    return 0;
}

/* The instance of a dissolving island back to the pool, or destroyed (its counters kept)
 * when it is large or the pool is full. */
static void give_back_solver(run_ctx *ctx, run_island *isl)
{
    void *solver = isl->solver;
    size_t peak = isl->solver_peak;
    isl->solver = NULL;
    if (peak <= POOL_LARGEST_Y && ctx->idle_held + peak <= ctx->idle_budget &&
        (ctx->n_idle < ctx->idle_capacity || grow_idle(ctx) == 0)) {
        ctx->idle[ctx->n_idle] = solver;
        ctx->idle_len[ctx->n_idle] = isl->island.n_y;
        ctx->idle_peak[ctx->n_idle++] = peak;
        ctx->idle_held += peak;
        return;
    }
    bk_solver_counters c;
    ctx->backend->counters(solver, &c);
    bk_solver_counters_add(&ctx->retired, &c);
    ctx->backend->destroy(solver);
}

/* A free island id with its arrays (kept from an earlier island when there is one). */
static int new_island(run_ctx *ctx, size_t n_y, size_t *id)
{
    if (ctx->n_free > 0) {
        *id = ctx->free_ids[--ctx->n_free];
    } else {
        if (ctx->islands_used == ctx->islands_capacity) {
            size_t cap = ctx->islands_capacity ? 2 * ctx->islands_capacity : 16;
            run_island **grown = realloc(ctx->islands, cap * sizeof *grown);
            if (!grown)
                return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for islands");
            ctx->islands = grown;
            size_t *ids = realloc(ctx->free_ids, cap * sizeof *ids);
            if (!ids || bk_heap_reserve(&ctx->island_queue, cap) != 0)
                return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for islands");
            ctx->free_ids = ids;
            ctx->islands_capacity = cap;
        }
        /* Each island on its own: back-ends keep a pointer to it (the problem's user). */
        run_island *isl = calloc(1, sizeof *isl);
        if (!isl)
            return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for islands");
        *id = ctx->islands_used++;
        ctx->islands[*id] = isl;
        isl->island.scene = &ctx->scene;
        isl->island.id = *id;
    }
    run_island *isl = ctx->islands[*id];
    int rc = take_solver(ctx, n_y, isl);
    if (rc != BK_OK) {
        ctx->free_ids[ctx->n_free++] = *id;
        return rc;
    }
    isl->live = 1;
    ctx->live_islands++;
    return BK_OK;
}

static void release_island(run_ctx *ctx, size_t id)
{
    run_island *isl = ctx->islands[id];
    bk_heap_remove(&ctx->island_queue, id);
    give_back_solver(ctx, isl);
    if (isl->capacity_y > POOL_LARGEST_Y) {
        /* A dissolved large island's arrays go too, for the reason large instances do. */
        bk_island_free(&isl->island);
        free(isl->y);
        free(isl->found);
        isl->y = isl->y_probe = isl->atol = NULL;
        isl->found = NULL;
        isl->capacity_y = isl->capacity_roots = 0;
    }
    isl->live = 0;
    isl->pending = 0;
    ctx->live_islands--;
    ctx->free_ids[ctx->n_free++] = id;
}

static int reserve_vectors(run_ctx *ctx, run_island *isl, size_t len)
{
    size_t n_y = bk_island_max_y(&ctx->scene, len);
    size_t n_roots = ctx->scene.roots_per_block * len;
    if (bk_island_reserve(&isl->island, len) != 0)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for an island of %zu blocks", len);
    if (!bk_capacity_fits(n_y, isl->capacity_y)) {
        /* One block: the island's vectors are touched together at every step. */
        double *block = realloc(isl->y, 3 * n_y * sizeof *block);
        if (!block)
            return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for an island of %zu blocks", len);
        isl->y = block;
        isl->y_probe = block + n_y;
        isl->atol = block + 2 * n_y;
        isl->capacity_y = n_y;
    }
    if (n_roots > 0 && !bk_capacity_fits(n_roots, isl->capacity_roots)) {
        int *found = realloc(isl->found, n_roots * sizeof *found);
        if (!found)
            return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for an island of %zu blocks", len);
        isl->found = found;
        isl->capacity_roots = n_roots;
    }
    return BK_OK;
}

/* (Re)start island id at t on its blocks' current state. */
static int start_island(run_ctx *ctx, size_t id, double t)
{
    run_island *isl = ctx->islands[id];
    bk_island *island = &isl->island;
    int rc = reserve_vectors(ctx, isl, island->len);
    if (rc != BK_OK)
        return rc;
    for (size_t k = 0; k < island->len; ++k)
        bk_heap_remove(&ctx->quiet, bk_island_block(island, k));
    bk_island_restart(island, t, isl->y);
    bk_island_tolerances(island, ctx->atol_x, ctx->atol_v, ctx->atol_state, ctx->atol_energy, isl->atol);
    isl->problem = (bk_ode_problem){
        .user = island,
        .rhs = bk_island_rhs,
        .jacobian = bk_island_jacobian,
        .rhs_split = bk_island_rhs_split,
        .jacobian_implicit = bk_island_jacobian_implicit,
        .roots = bk_island_roots,
        .n_roots = bk_island_n_roots(island),
        .root_direction = island->root_direction,
        .half_bandwidth = island->half_bandwidth,
        /* Pairs lead the layout only when no friction state is interleaved; the full
         * layout's stuck pairs are no oscillators, so it declares no structure. */
        .n_pairs = ctx->model->n_friction_state == 0 && !ctx->scene.full_layout ? island->n_active : 0,
        .pair_mass = island->active_mass,
        .affine = island->affine,
        .differential_id = ctx->scene.full_layout ? island->differential_id : NULL,
    };
    if (island->n_y > isl->solver_peak)
        isl->solver_peak = island->n_y;
    rc = ctx->backend->start(isl->solver, &isl->problem, t, isl->y, isl->atol, island->n_y,
                             bk_run_stop_time(ctx), ctx->err);
    if (rc != BK_OK)
        return rc;
    ctx->stats->integrator_starts++;
    isl->stepped = 0;
    isl->pending = 0;
    isl->t_reached = t;
    bk_run_catalog_island_start(ctx, isl);
    bk_heap_set(&ctx->island_queue, id, t);
    return BK_OK;
}

/* The island's state at t into the chain's arrays: its own vector where it stands at t,
 * else dense output (t lies in its last step: see the scheduler in run.c); for an output
 * row (for_row), the back-end's output-row interpolant where it has one. */
static int unpack_island(run_ctx *ctx, run_island *isl, double t, int for_row, bk_energy *increments)
{
    const double *y = isl->y;
    if (t != isl->t_reached) {
        const bk_solver_backend *backend = ctx->backend;
        int rc = (for_row && backend->sample ? backend->sample : backend->interpolate)(
            isl->solver, t, isl->y_probe, ctx->err);
        if (rc != BK_OK)
            return rc;
        y = isl->y_probe;
    }
    bk_island_unpack(&isl->island, t, y, increments);
    return BK_OK;
}

int bk_run_unpack_all(run_ctx *ctx, double t)
{
    bk_energy islands = {0};
    for (size_t id = 0; id < ctx->islands_used; ++id) {
        run_island *isl = ctx->islands[id];
        if (!isl->live)
            continue;
        bk_energy increments;
        int rc = unpack_island(ctx, isl, t, 1, &increments);
        if (rc != BK_OK)
            return rc;
        bk_energy_add(&islands, &increments);
    }
    bk_run_energy_totals(ctx, t, &islands);
    return BK_OK;
}

/* --------------------------------------------------------------- the partition --- */

int bk_run_dissolve(run_ctx *ctx, size_t id, double t, int taken)
{
    run_island *isl = ctx->islands[id];
    if (!taken) {
        bk_energy increments;
        int rc = unpack_island(ctx, isl, t, 0, &increments);
        if (rc != BK_OK)
            return rc;
        bk_energy_add(&ctx->closed, &increments);
    }
    bk_scene *scene = &ctx->scene;
    for (size_t k = 0; k < isl->island.len; ++k) {
        size_t i = bk_island_block(&isl->island, k);
        scene->island_of[i] = BK_NO_ISLAND;
        scene->slot[i] = BK_NO_SLOT;
    }
    release_island(ctx, id);
    return BK_OK;
}

int bk_run_found_island(run_ctx *ctx, const size_t *blocks, size_t len, double t)
{
    size_t id = BK_NO_ISLAND;
    int rc = new_island(ctx, bk_island_y_length(&ctx->scene, blocks, len), &id);
    if (rc != BK_OK)
        return rc;
    run_island *isl = ctx->islands[id];
    if ((rc = reserve_vectors(ctx, isl, len)) != BK_OK)
        return rc;
    memcpy(isl->island.blocks, blocks, len * sizeof *blocks);
    isl->island.len = len;
    return start_island(ctx, id, t);
}

/* ------------------------------------------------------------- island events --- */

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
    if (lo < isl->island.t_ref)
        lo = isl->island.t_ref;
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
    int step = ctx->backend->step(isl->solver, &t_reached, isl->y, ctx->err);
    if (step < 0)
        return step;
    isl->stepped = 1;
    isl->t_reached = t_reached;
    ctx->restart_work += (double)isl->island.len;
    int rc = check_finite(ctx, isl, t_reached);
    if (rc != BK_OK)
        return rc;
    if (++ctx->steps_since_row > ctx->options.max_steps)
        return BK_FAIL(ctx->err, BK_ERR_MAX_STEPS,
                       "more than %ld solver steps since the last output row or transition "
                       "(t = %.17g s, now at t = %.17g s); raise [solver] max_steps or loosen rtol",
                       ctx->options.max_steps, ctx->t_last_row, t_reached);
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
    if ((rc = bk_run_catalog_island_step(ctx, isl)) != BK_OK)
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

int bk_run_island_event(run_ctx *ctx, size_t id)
{
    run_island *isl = ctx->islands[id];
    const bk_scene *scene = &ctx->scene;
    size_t R = scene->roots_per_block;
    double t = isl->t_event;
    bk_energy increments;
    int rc = unpack_island(ctx, isl, t, 0, &increments);
    if (rc != BK_OK)
        return rc;
    bk_energy_add(&ctx->closed, &increments);
    const bk_island *island = &isl->island;
    /* Every root restarts the island.  A minimum that hid no stop disarms its root until the
     * block decelerates again, so the restart does not begin on a zero of it. */
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
            if ((rc = bk_run_catalog_crossing(ctx, t, i)) != BK_OK)
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
    if (changed && ctx->event_rows)
        ctx->t_row_due = t;
    if (!changed)
        return start_island(ctx, id, t);
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
