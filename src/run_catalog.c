/* The event catalog during a run: the builder (bksim/catalog.h) fed with every transition as
 * it happens (run_transitions.c hands them on, with the threshold crossings that stand in for
 * transitions of laws without a stuck state), completed events handed to the sink, and the
 * largest slip rate of each event.
 *
 * The largest slip rate.  Between restarts a block's speed |v| is smooth, so its maxima are
 * at step ends or where d|v|/dt falls through zero inside a step.  Each step end is looked at
 * (O(slipping blocks)); a maximum inside a step is first estimated by the cubic Hermite
 * interpolant of |v| and d|v|/dt at the step's two ends, and only the step's largest estimate,
 * and only if it could raise the event's maximum, is located on the back-end's own dense
 * output (Brent).  So a chain's synchronous maxima cost one location per step, not one per
 * block, and the value is the interpolant's: exact for the exact stepper, within the
 * tolerances otherwise. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "layout.h"
#include "run_ctx.h"

static double applied_force(const void *user, size_t i)
{
    const run_ctx *ctx = user;
    double driver_pos = bk_driver_position(&ctx->model->driver, ctx->t_catalog);
    return bk_scene_applied_force(&ctx->scene, i, driver_pos);
}

int bk_run_catalog_init(run_ctx *ctx, const bk_checkpoint *from)
{
    const bk_config *config = ctx->config;
    if (!config->output.events || (from && !from->catalog))
        return BK_OK; /* a checkpoint from before catalogs: the resumed run writes none */
    bk_scene *scene = &ctx->scene;
    size_t n = scene->n;
    const bk_model *m = ctx->model;
    ctx->catalog = bk_catalog_create_lattice(m->rows, m->cols, m->boundary_rows == BK_BOUNDARY_PERIODIC,
                                             m->boundary_cols == BK_BOUNDARY_PERIODIC,
                                             config->catalog.magnitude_offset);
    ctx->rate_v = malloc(n * sizeof *ctx->rate_v);
    ctx->rate_a = malloc(n * sizeof *ctx->rate_a);
    int creeping = 0;
    for (size_t i = 0; i < n; ++i)
        creeping |= !scene->can_stick[i];
    if (creeping) {
        scene->slip_threshold = config->catalog.slip_rate_threshold;
        scene->above = calloc(n, sizeof *scene->above);
    }
    if (!ctx->catalog || !ctx->rate_v || !ctx->rate_a || (creeping && !scene->above))
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the event catalog of %zu blocks", n);
    if (ctx->checkpoint_interval > 0.0 || ctx->checkpoint_work > 0.0) {
        bk_catalog_state *s = &ctx->catalog_state;
        s->x_onset = malloc(n * sizeof *s->x_onset);
        s->first_force = malloc(n * sizeof *s->first_force);
        s->last_force = malloc(n * sizeof *s->last_force);
        s->involved = malloc(n * sizeof *s->involved);
        s->slipping = malloc(n * sizeof *s->slipping);
        if (!s->x_onset || !s->first_force || !s->last_force || !s->involved || !s->slipping)
            return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the event catalog of %zu blocks", n);
    }
    if (from) {
        if (bk_catalog_restore(ctx->catalog, from->catalog) != BK_OK)
            return BK_FAIL(ctx->err, BK_ERR_INVALID,
                           "the checkpoint's event catalog does not hold together (a slipping block "
                           "outside the open event, or an open event without blocks)");
        ctx->events = ctx->events_resumed = from->catalog->events;
        for (size_t i = 0; i < n && scene->above; ++i)
            scene->above[i] = !scene->can_stick[i] && from->catalog->slipping[i];
        return BK_OK;
    }
    /* Blocks that move at t = 0 slip from the start; resting ones start slipping through
     * transitions at t = 0, which the builder then sees. */
    int8_t *modes = malloc(n * sizeof *modes);
    if (!modes)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the event catalog of %zu blocks", n);
    for (size_t i = 0; i < n; ++i) {
        if (scene->above)
            scene->above[i] = !scene->can_stick[i] && fabs(scene->v[i]) > scene->slip_threshold;
        int slips = scene->can_stick[i] ? scene->v[i] != 0.0 : scene->above[i];
        modes[i] = slips ? (int8_t)BK_MODE_SLIP_POS : (int8_t)BK_MODE_STICK; /* the builder asks no more */
    }
    ctx->t_catalog = 0.0;
    int rc = bk_catalog_begin(ctx->catalog, 0.0, modes, scene->x, scene->v, applied_force, ctx);
    free(modes);
    if (rc != BK_OK)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the event catalog");
    return BK_OK;
}

void bk_run_catalog_free(run_ctx *ctx)
{
    bk_catalog_free(ctx->catalog);
    free(ctx->rate_v);
    free(ctx->rate_a);
    free(ctx->scene.above);
    ctx->scene.above = NULL;
    bk_catalog_state *s = &ctx->catalog_state;
    free(s->x_onset);
    free(s->first_force);
    free(s->last_force);
    free(s->involved);
    free(s->slipping);
}

static int emit(run_ctx *ctx, const bk_event *event)
{
    ctx->events++;
    int rc = bk_run_count_bytes(ctx, BK_EVENT_RECORD_BYTES, event->t_end);
    if (rc == BK_OK && ctx->sink && ctx->sink->event) {
        rc = ctx->sink->event(ctx->sink->self, event, ctx->err);
        if (rc != BK_OK)
            rc = rc < 0 ? rc : BK_ERR_SINK;
    }
    return rc;
}

int bk_run_catalog_transition(run_ctx *ctx, const bk_transition *transition)
{
    if (!ctx->catalog)
        return BK_OK;
    bk_event event;
    int done = 0;
    if (bk_catalog_add(ctx->catalog, transition, &event, &done) != BK_OK)
        return BK_FAIL(ctx->err, BK_ERR_NOMEM, "out of memory for the event catalog at t = %.17g s",
                       transition->t);
    return done ? emit(ctx, &event) : BK_OK;
}

int bk_run_catalog_finish(run_ctx *ctx, double t)
{
    if (!ctx->catalog)
        return BK_OK;
    bk_event event;
    ctx->t_catalog = t;
    int rc = bk_catalog_finish(ctx->catalog, t, ctx->scene.x, applied_force, ctx, &event);
    if (rc < 0)
        return BK_FAIL(ctx->err, rc, "out of memory closing the last event at t = %.17g s", t);
    return rc == 1 ? emit(ctx, &event) : BK_OK;
}

int bk_run_catalog_save(run_ctx *ctx, bk_catalog_state **state)
{
    *state = NULL;
    if (!ctx->catalog)
        return BK_OK;
    bk_catalog_save(ctx->catalog, &ctx->catalog_state);
    ctx->catalog_state.events = ctx->events;
    *state = &ctx->catalog_state;
    return bk_run_ruptures_save(ctx, &ctx->catalog_state);
}

/* ------------------------------------------------------------ largest slip rate --- */

void bk_run_catalog_island_start(run_ctx *ctx, const run_island *isl)
{
    if (!ctx->catalog)
        return;
    const bk_scene *scene = &ctx->scene;
    const bk_island *island = &isl->island;
    double fastest = 0.0;
    for (size_t k = 0; k < island->n_active; ++k) {
        size_t i = island->active[k];
        ctx->rate_v[i] = isl->y[scene->slot[i] + 1];
        ctx->rate_a[i] = bk_run_speed_rate(isl, i, island->t_ref, isl->y);
        fastest = fmax(fastest, fabs(ctx->rate_v[i]));
    }
    bk_catalog_slip_rate(ctx->catalog, fastest);
}

int bk_run_catalog_island_step(run_ctx *ctx, run_island *isl)
{
    if (!ctx->catalog || bk_catalog_max_slip_rate(ctx->catalog) < 0.0)
        return BK_OK;
    const bk_scene *scene = &ctx->scene;
    const bk_island *island = &isl->island;
    double lo, hi;
    const double *y;
    int rc = bk_run_last_step(ctx, isl, &lo, &hi, &y);
    if (rc != BK_OK)
        return rc;
    double fastest = 0.0, best_estimate = -1.0;
    size_t best = SIZE_MAX;
    for (size_t k = 0; k < island->n_active; ++k) {
        size_t i = island->active[k];
        double v = y[scene->slot[i] + 1], rate = bk_run_speed_rate(isl, i, hi, y);
        fastest = fmax(fastest, fabs(v));
        if (ctx->rate_a[i] > 0.0 && rate < 0.0 && hi > lo) {
            double estimate = bk_run_hermite_peak(fabs(ctx->rate_v[i]), ctx->rate_a[i], fabs(v), rate, hi - lo);
            if (estimate > best_estimate) {
                best_estimate = estimate;
                best = i;
            }
        }
        ctx->rate_v[i] = v;
        ctx->rate_a[i] = rate;
    }
    bk_catalog_slip_rate(ctx->catalog, fastest);
    if (best == SIZE_MAX || best_estimate <= bk_catalog_max_slip_rate(ctx->catalog))
        return BK_OK;
    bk_block_probe probe = {ctx, isl, best, BK_OK};
    gsl_function fn = {bk_run_speed_rate_probe, &probe};
    double f_lo = bk_run_speed_rate_probe(lo, &probe), f_hi = bk_run_speed_rate_probe(hi, &probe);
    double t_peak = hi;
    if (probe.status == BK_OK && f_lo > 0.0 && f_hi < 0.0)
        t_peak = bk_run_zero_after(ctx, &fn, lo, hi);
    if (probe.status != BK_OK)
        return probe.status;
    rc = ctx->backend->interpolate(isl->solver, t_peak, isl->y_probe, ctx->err);
    if (rc != BK_OK)
        return rc;
    bk_catalog_slip_rate(ctx->catalog, isl->y_probe[scene->slot[best] + 1]);
    return BK_OK;
}
