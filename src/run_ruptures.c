/* The rupture catalog during a run: the builder (bksim/rupture.h) fed with every transition
 * (run_transitions.c hands them on, threshold crossings included), completed ruptures handed
 * to the sink, and each slipping block's speed sampled from its island's dense output for the
 * moment-rate function and the largest slip rate.
 *
 * Sampling.  After each step [lo, hi] of an island, every block of it that slips in an open
 * episode gets a sample at hi and at k - 1 points evenly inside the step.  k comes from the
 * step's own ends: the trapezoid rule's error on a cubic with |v| and d|v|/dt as at the ends
 * is h^2 (d0 - d1) / 12 per block, and k is the smallest that brings the sum below RATE_TOL
 * of the step's integral (so the function integrates to the potency well within 1e-3), at
 * most MAX_PIECES; without /rupture_rate k = 1.  A speed maximum inside the step (d|v|/dt
 * changing sign from + to -) whose cubic estimate could raise the episode's largest speed is
 * located on the dense output (Brent) and sampled too: the largest slip rate is the dense
 * output's, exact for the exact stepper.  An island restarted at t (a merge, a checkpoint)
 * samples its blocks at t again, which drops samples its discarded last step took past t;
 * so samples before a step's start are settled (bk_ruptures_settle), and the builder may sum
 * them into the rupture's rate as it goes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capacity.h"
#include "layout.h"
#include "run_ctx.h"

#define RATE_TOL 4e-4
#define MAX_PIECES 128

static double applied_force(const void *user, size_t i)
{
    const run_ctx *ctx = user;
    double driver_pos = bk_driver_position(&ctx->model->driver, ctx->t_rupture_force);
    return bk_scene_applied_force(&ctx->scene, i, driver_pos);
}

static int emit(void *user, const bk_rupture *rupture, const bk_rupture_block *blocks, size_t n_blocks,
                const bk_rupture_rate *rate, size_t n_rate)
{
    run_ctx *ctx = user;
    double bytes = BK_RUPTURE_RECORD_BYTES + (double)n_blocks * BK_RUPTURE_BLOCK_RECORD_BYTES +
                   (double)n_rate * BK_RUPTURE_RATE_RECORD_BYTES;
    int rc = bk_run_count_bytes(ctx, bytes, rupture->t_end);
    if (rc == BK_OK && ctx->sink && ctx->sink->rupture) {
        rc = ctx->sink->rupture(ctx->sink->self, rupture, blocks, n_blocks, rate, n_rate, ctx->err);
        if (rc != BK_OK)
            rc = rc < 0 ? rc : BK_ERR_SINK;
    }
    return rc;
}

/* A builder's failure: out of memory is ours to report; the sink reported its own. */
static int builder_failed(run_ctx *ctx, int rc, double t)
{
    if (rc == BK_ERR_NOMEM)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the rupture catalog at t = %.17g s", t);
    if (rc == BK_ERR_INVALID)
        return BK_FAIL(ctx->err, BK_ERR_INVALID, "rupture catalog: a transition of a block outside the chain "
                       "at t = %.17g s", t);
    return rc;
}

int bk_run_ruptures_init(run_ctx *ctx, const bk_checkpoint *from)
{
    const bk_config *config = ctx->config;
    if (!ctx->catalog)
        return BK_OK; /* no catalog at all ([output] events = false) */
    /* A checkpoint written before ruptures were catalogued: the resumed run writes none. */
    if (from && (!from->catalog || from->catalog->rupture_state_count <= 0))
        return BK_OK;
    const bk_model *m = ctx->model;
    size_t n = ctx->scene.n;
    ctx->ruptures = bk_ruptures_create(m->rows, m->cols, m->boundary_rows == BK_BOUNDARY_PERIODIC,
                                       m->boundary_cols == BK_BOUNDARY_PERIODIC, config->catalog.magnitude_offset,
                                       config->catalog.rupture_rate, emit, ctx);
    ctx->rupture_v = malloc(n * sizeof *ctx->rupture_v);
    ctx->rupture_a = malloc(n * sizeof *ctx->rupture_a);
    if (!ctx->ruptures || !ctx->rupture_v || !ctx->rupture_a)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the rupture catalog of %zu blocks", n);
    if (from) {
        int rc = bk_ruptures_restore(ctx->ruptures, from->catalog->rupture_state,
                                     (size_t)from->catalog->rupture_state_count);
        if (rc == BK_ERR_NOMEM)
            return BK_FAIL(ctx->err, rc, "out of memory restoring the rupture catalog");
        if (rc != BK_OK)
            return BK_FAIL(ctx->err, BK_ERR_INVALID, "the checkpoint's rupture catalog does not hold together");
        return BK_OK;
    }
    /* As the event catalog: blocks moving at t = 0 slip from the start. */
    const bk_scene *scene = &ctx->scene;
    uint8_t *slipping = malloc(n * sizeof *slipping);
    if (!slipping)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the rupture catalog of %zu blocks", n);
    for (size_t i = 0; i < n; ++i)
        slipping[i] = (uint8_t)(scene->can_stick[i] ? scene->v[i] != 0.0 : scene->above[i]);
    ctx->t_rupture_force = 0.0;
    int rc = bk_ruptures_begin(ctx->ruptures, 0.0, slipping, scene->x, scene->v, applied_force, ctx);
    free(slipping);
    return rc == BK_OK ? BK_OK : builder_failed(ctx, rc, 0.0);
}

void bk_run_ruptures_free(run_ctx *ctx)
{
    bk_ruptures_free(ctx->ruptures);
    ctx->ruptures = NULL;
    free(ctx->rupture_v);
    free(ctx->rupture_a);
    free(ctx->rupture_saved);
    free(ctx->rupture_steps);
}

int bk_run_ruptures_transition(run_ctx *ctx, const bk_transition *transition)
{
    if (!ctx->ruptures)
        return BK_OK;
    int rc = bk_ruptures_add(ctx->ruptures, transition);
    return rc == BK_OK ? BK_OK : builder_failed(ctx, rc, transition->t);
}

int bk_run_ruptures_finish(run_ctx *ctx, double t)
{
    if (!ctx->ruptures)
        return BK_OK;
    ctx->t_rupture_force = t;
    int rc = bk_ruptures_finish(ctx->ruptures, t, ctx->scene.x, ctx->scene.v, applied_force, ctx);
    return rc == BK_OK ? BK_OK : builder_failed(ctx, rc, t);
}

int bk_run_ruptures_save(run_ctx *ctx, bk_catalog_state *state)
{
    state->rupture_state = NULL;
    state->rupture_state_count = 0;
    if (!ctx->ruptures)
        return BK_OK;
    size_t need = bk_ruptures_save(ctx->ruptures, NULL, 0);
    double *buf = bk_grow_array(ctx->rupture_saved, &ctx->rupture_saved_capacity, need, sizeof *buf, 64);
    if (!buf)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory saving the rupture catalog");
    ctx->rupture_saved = buf;
    bk_ruptures_save(ctx->ruptures, buf, need);
    state->rupture_state = buf;
    state->rupture_state_count = (long)need;
    return BK_OK;
}

int bk_run_ruptures_island_start(run_ctx *ctx, const run_island *isl)
{
    if (!ctx->ruptures)
        return BK_OK;
    const bk_scene *scene = &ctx->scene;
    const bk_island *island = &isl->island;
    for (size_t k = 0; k < island->n_active; ++k) {
        size_t i = island->active[k];
        ctx->rupture_v[i] = isl->y[scene->slot[i] + 1];
        ctx->rupture_a[i] = bk_run_speed_rate(isl, i, island->t_ref, isl->y);
        if (bk_ruptures_sample(ctx->ruptures, i, island->t_ref, fabs(ctx->rupture_v[i])) != BK_OK)
            return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the rupture catalog at t = %.17g s",
                           island->t_ref);
    }
    return BK_OK;
}

int bk_run_ruptures_crossed(run_ctx *ctx, size_t i, double t)
{
    /* Its speed and d|v|/dt at t are the last step's end values, kept while it crept. */
    if (ctx->ruptures && bk_ruptures_sample(ctx->ruptures, i, t, fabs(ctx->scene.v[i])) != BK_OK)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the rupture catalog at t = %.17g s", t);
    return BK_OK;
}

/* A slipping block's step: its speed and d|v|/dt at the step's end, and its interior peak. */
typedef struct block_step {
    size_t block;
    double v1, a1;
    double t_peak, v_peak;  /* NAN: no peak to sample */
} block_step;

/* The pieces a step of length h needs (see the top of this file). */
static size_t pieces(const run_ctx *ctx, const block_step *steps, size_t n, double h)
{
    if (!ctx->config->catalog.rupture_rate || n == 0 || !(h > 0.0))
        return 1;
    double error = 0.0, integral = 0.0, scale = 0.0;
    for (size_t k = 0; k < n; ++k) {
        size_t i = steps[k].block;
        double u0 = fabs(ctx->rupture_v[i]), u1 = fabs(steps[k].v1);
        double d0 = ctx->rupture_a[i], d1 = steps[k].a1;
        error += h * h * fabs(d0 - d1) / 12.0;
        integral += h * (u0 + u1) / 2.0 + h * h * (d0 - d1) / 12.0;
        scale += h * fmax(u0, u1);
    }
    double reference = fmax(fabs(integral), 1e-3 * scale);
    if (!(error > 0.0) || !(reference > 0.0))
        return 1;
    double k = ceil(sqrt(error / (RATE_TOL * reference)));
    return !(k >= 1.0) ? 1 : k > MAX_PIECES ? MAX_PIECES : (size_t)k; /* NaN: 1 */
}

int bk_run_ruptures_island_step(run_ctx *ctx, run_island *isl)
{
    if (!ctx->ruptures)
        return BK_OK;
    const bk_scene *scene = &ctx->scene;
    const bk_island *island = &isl->island;
    double lo, hi;
    const double *y;
    int rc = bk_run_last_step(ctx, isl, &lo, &hi, &y);
    if (rc != BK_OK)
        return rc;
    block_step *steps = bk_grow_array(ctx->rupture_steps, &ctx->rupture_steps_capacity,
                                      island->n_active ? island->n_active : 1, sizeof *steps, 16);
    if (!steps)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the rupture catalog at t = %.17g s", hi);
    ctx->rupture_steps = steps;
    size_t n = 0;
    for (size_t k = 0; k < island->n_active; ++k) {
        size_t i = island->active[k];
        double v1 = y[scene->slot[i] + 1], a1 = bk_run_speed_rate(isl, i, hi, y);
        if (bk_ruptures_slipping(ctx->ruptures, i)) {
            steps[n++] = (block_step){i, v1, a1, NAN, NAN};
            /* Nothing before the step's start can be taken back (a restart falls inside it). */
            bk_ruptures_settle(ctx->ruptures, i, lo);
        }
        else {
            ctx->rupture_v[i] = v1;
            ctx->rupture_a[i] = a1;
        }
    }
    double h = hi - lo;
    /* Interior maxima that could raise an episode's largest speed, located on the dense
     * output (before the samples, whose interpolations reuse y_probe). */
    for (size_t k = 0; k < n && h > 0.0; ++k) {
        size_t i = steps[k].block;
        double a0 = ctx->rupture_a[i];
        if (!(a0 > 0.0 && steps[k].a1 < 0.0))
            continue;
        double estimate = bk_run_hermite_peak(fabs(ctx->rupture_v[i]), a0, fabs(steps[k].v1), steps[k].a1, h);
        if (estimate <= bk_ruptures_episode_peak(ctx->ruptures, i))
            continue;
        bk_block_probe probe = {ctx, isl, i, BK_OK};
        gsl_function fn = {bk_run_speed_rate_probe, &probe};
        double f_lo = bk_run_speed_rate_probe(lo, &probe), f_hi = bk_run_speed_rate_probe(hi, &probe);
        if (probe.status != BK_OK)
            return probe.status;
        if (!(f_lo > 0.0 && f_hi < 0.0))
            continue;
        double t_peak = bk_run_zero_after(ctx, &fn, lo, hi);
        if (probe.status != BK_OK)
            return probe.status;
        rc = ctx->backend->interpolate(isl->solver, t_peak, isl->y_probe, ctx->err);
        if (rc != BK_OK)
            return rc;
        if (t_peak > lo && t_peak < hi) {
            steps[k].t_peak = t_peak;
            steps[k].v_peak = fabs(isl->y_probe[scene->slot[i] + 1]);
        }
    }
    size_t count = pieces(ctx, steps, n, h);
    rc = BK_OK;
    for (size_t j = 1; j <= count && rc == BK_OK; ++j) {
        double t = j == count ? hi : lo + h * (double)j / (double)count;
        const double *yj = j == count ? y : NULL;
        if (!yj) {
            if ((rc = ctx->backend->interpolate(isl->solver, t, isl->y_probe, ctx->err)) != BK_OK)
                return rc;
            yj = isl->y_probe;
        }
        for (size_t k = 0; k < n && rc == BK_OK; ++k) {
            size_t i = steps[k].block;
            if (steps[k].t_peak < t) { /* NAN compares false */
                rc = bk_ruptures_sample(ctx->ruptures, i, steps[k].t_peak, steps[k].v_peak);
                steps[k].t_peak = NAN;
            }
            if (rc == BK_OK)
                rc = bk_ruptures_sample(ctx->ruptures, i, t, fabs(j == count ? steps[k].v1 : yj[scene->slot[i] + 1]));
        }
    }
    if (rc != BK_OK)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the rupture catalog at t = %.17g s", hi);
    for (size_t k = 0; k < n; ++k) {
        ctx->rupture_v[steps[k].block] = steps[k].v1;
        ctx->rupture_a[steps[k].block] = steps[k].a1;
    }
    return BK_OK;
}
