/* The energy audit's books.  The driver's work on a stuck block is the energy its driver
 * spring gains (the block does not move), so each stuck interval's work is known in closed
 * form when it ends, and a slipping block's work and dissipation are integrated by its
 * island.  The totals are kept as what has finished plus what is open, so an event costs
 * O(1) in the books and only a row (O(N) anyway) sums the open stuck intervals. */
#include "run_ctx.h"

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
