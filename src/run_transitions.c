/* Transitions as the run hands them on: the chattering guard and the counters, then a
 * buffer of the current instant flushed in block order when it ends, to the catalog builder
 * (run_catalog.c) and to the sink's /transitions.  For a law without a stuck state the
 * slip-rate threshold crossings enter the same stream, so that the catalog sees one ordered
 * sequence either way. */
#include "capacity.h"
#include "layout.h"
#include "run_ctx.h"

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
    if (!written && !ctx->catalog && !ctx->ruptures)
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

/* The event and the rupture catalogs see every transition, crossings included. */
static int to_catalogs(run_ctx *ctx, const bk_transition *transition)
{
    int rc = bk_run_catalog_transition(ctx, transition);
    return rc == BK_OK ? bk_run_ruptures_transition(ctx, transition) : rc;
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
        int rc = to_catalogs(ctx, &ctx->instant[k]);
        if (rc == BK_OK && written)
            rc = ctx->sink->transition(ctx->sink->self, &ctx->instant[k], ctx->err);
        if (rc != BK_OK)
            return rc < 0 ? rc : BK_ERR_SINK;
    }
    return BK_OK;
}

/* For the builder: stuck or slipping, and for a law without a stuck state below or above the
 * threshold. */
static int8_t catalog_mode(const run_ctx *ctx, size_t i)
{
    const bk_scene *scene = &ctx->scene;
    if (scene->can_stick[i])
        return scene->mode[i];
    return scene->above[i] ? (int8_t)BK_MODE_SLIP_POS : (int8_t)BK_MODE_STICK;
}

int bk_run_record_crossing(run_ctx *ctx, double t, size_t i, int rising)
{
    bk_scene *scene = &ctx->scene;
    if (scene->above[i] == (uint8_t)(rising != 0))
        return BK_OK; /* already on that side: the crossing was recorded */
    if (ctx->n_instant > 0 && t != ctx->t_instant) {
        int rc = bk_run_flush_instant(ctx);
        if (rc != BK_OK)
            return rc;
    }
    double driver_pos = bk_driver_position(&ctx->model->driver, t);
    int8_t from = catalog_mode(ctx, i);
    scene->above[i] = (uint8_t)(rising != 0);
    ctx->steps_since_row = 0; /* progress, as a transition is, for the hang guard */
    bk_transition crossing = {
        .t = t,
        .block = (int32_t)i,
        .from = from,
        .to = catalog_mode(ctx, i),
        .x = scene->x[i],
        .v = scene->v[i],
        .force = bk_scene_applied_force(scene, i, driver_pos),
    };
    return to_catalogs(ctx, &crossing);
}
