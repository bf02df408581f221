/* The time-series rows a run hands to its sink: regular samples, and the two rows of a
 * transition instant (the state just before its transitions, then just after). */
#include "run_ctx.h"

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
