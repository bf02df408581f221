/* The islands and quiet blocks of the partition (scene.h; run_partition.c builds it, and
 * run_events.c says what happens to them): the islands by id, each with its back-end
 * instance from a pool; an island founded, (re)started, dissolved; its state unpacked into
 * the chain's arrays.  Quiet blocks wait in a priority queue by their breakaway time
 * (run_quiet.c).  Nothing here loops over the chain except bk_run_unpack_all (output rows).
 *
 * Why the partition is safe: a quiet block's neighbours are stuck, so its applied force is
 * affine in the driver's position until one of them moves, which only happens through an
 * event that rebuilds the partition around it (and recomputes its failure time).  An island
 * depends on blocks outside it only through stuck ones, so islands integrated to different
 * times never see each other: the scheduler (run.c) always handles the earliest pending
 * event first, and every island's last step then contains that time, so its state there is
 * at hand (dense output) when a merge needs it. */
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_roots.h>

#include "capacity.h"
#include "run_ctx.h"

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
    return ctx->batch && ctx->brent ? 0 : -1;
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

void bk_run_drain_pool(run_ctx *ctx)
{
    for (size_t k = 0; k < ctx->n_idle; ++k) {
        bk_solver_counters c;
        ctx->backend->counters(ctx->idle[k], &c);
        bk_solver_counters_add(&ctx->retired, &c);
        ctx->backend->destroy(ctx->idle[k]);
    }
    ctx->n_idle = 0;
    ctx->idle_held = 0;
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

int bk_run_start_island(run_ctx *ctx, size_t id, double t)
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
    /* The velocity rows of blocks without mass are the force balance's time derivative in
     * the ODE layout, whose Jacobian island.c does not write: difference quotients there. */
    int exact_jacobian = island->n_massless == 0 || ctx->scene.full_layout;
    isl->problem = (bk_ode_problem){
        .user = island,
        .rhs = bk_island_rhs,
        .jacobian = exact_jacobian ? bk_island_jacobian : NULL,
        .rhs_split = bk_island_rhs_split,
        .jacobian_implicit = exact_jacobian ? bk_island_jacobian_implicit : NULL,
        .roots = bk_island_roots,
        .n_roots = bk_island_n_roots(island),
        .root_direction = island->root_direction,
        .half_bandwidth = island->half_bandwidth,
        /* Pairs lead the layout only when no friction state is interleaved; the full
         * layout's stuck pairs are no oscillators, so it declares no structure. */
        .n_pairs = ctx->model->n_friction_state == 0 && !ctx->scene.full_layout ? island->n_active : 0,
        .pair_mass = island->active_mass,
        .affine = island->affine,
        /* the last energy increment, when damped, is the dashpots' (island.c) */
        .dissipation_last = ctx->scene.damped,
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
    isl->t_resume = t;
    if (ctx->scene.segmented && (rc = bk_run_segment_started(ctx, isl)) != BK_OK)
        return rc;
    bk_run_catalog_island_start(ctx, isl);
    if ((rc = bk_run_ruptures_island_start(ctx, isl)) != BK_OK)
        return rc;
    bk_heap_set(&ctx->island_queue, id, t);
    return BK_OK;
}

int bk_run_unpack_island(run_ctx *ctx, run_island *isl, double t, int for_row, bk_energy *increments)
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
        int rc = bk_run_unpack_island(ctx, isl, t, 1, &increments);
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
        int rc = bk_run_unpack_island(ctx, isl, t, 0, &increments);
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
    return bk_run_start_island(ctx, id, t);
}
