/* The run's clock and limits, asked by every part of the run loop: the wall clock, the
 * progress callback (which may ask the run to stop) and the wall-time limit, the [output]
 * max_bytes budget, and the times every integrator must stop at (the next restart point,
 * a driver breakpoint, t_end).  Nothing here calls into another part of the run loop. */
#include <math.h>
#include <time.h>

#include "layout.h"
#include "run_ctx.h"

double bk_run_wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int bk_run_report_progress(run_ctx *ctx, double t)
{
    if (ctx->progress) {
        bk_progress report = {
            .t = ctx->t_progress = fmax(ctx->t_progress, t),
            .t_end = ctx->t_end,
            .t_resumed = ctx->t_resumed,
            .transitions = ctx->stats->transitions,
            .events = ctx->catalog ? ctx->events : -1,
            .events_resumed = ctx->events_resumed,
        };
        int asked = ctx->progress(ctx->progress_user, &report);
        if (asked == BK_PROGRESS_CHECKPOINT_AND_STOP && bk_run_has_restart_points(ctx)) {
            /* Another restart point than the run's own would change the run: go on to the
             * next one (bk_run_restart_all stops there), within the grace time. */
            double now = bk_run_wall_seconds();
            if (!ctx->stop_at_restart) {
                ctx->stop_at_restart = 1;
                ctx->wall_stop_asked = now;
            } else if (now - ctx->wall_stop_asked > BK_STOP_GRACE) {
                return BK_FAIL(ctx->err, BK_ERR_INTERRUPTED,
                               "run interrupted at t = %.17g s: its next restart point was not reached within "
                               "%g s of the request to stop, so none was written (the last checkpoint stays)",
                               t, BK_STOP_GRACE);
            }
        } else if (asked != 0) {
            return BK_FAIL(ctx->err, BK_ERR_INTERRUPTED, "run interrupted at t = %.17g s", t);
        }
    }
    double limit = ctx->config->wall_time_limit;
    if (limit > 0.0 && bk_run_wall_seconds() - ctx->wall_start > limit)
        return BK_FAIL(ctx->err, BK_ERR_INTERRUPTED,
                       "[run] wall_time_limit = %g s reached at t = %.17g s of %g s", limit, t, ctx->t_end);
    return BK_OK;
}

double bk_run_checkpoint_time(const run_ctx *ctx)
{
    double t = ctx->checkpoint_interval > 0.0 ? (double)ctx->next_checkpoint * ctx->checkpoint_interval
                                              : ctx->t_restart;
    return t < ctx->t_end ? t : INFINITY;
}

double bk_run_stop_time(const run_ctx *ctx)
{
    double t_stop = fmin(bk_run_checkpoint_time(ctx), ctx->t_breakpoint);
    return t_stop < ctx->t_end ? t_stop : ctx->t_end;
}

/* The [output] max_bytes guard counts what is written, event rows and transitions too:
 * their number is not known before the run. */
int bk_run_count_bytes(run_ctx *ctx, double bytes, double t)
{
    ctx->bytes_written += bytes;
    if (ctx->bytes_written <= ctx->max_bytes)
        return BK_OK;
    return BK_FAIL(ctx->err, BK_ERR_LIMIT,
                   "[output] max_bytes = %.3g B reached at t = %.17g s: %ld rows of %.3g B, %ld "
                   "transitions of %d B and %ld events of %d B; raise max_bytes, sample less often, or "
                   "write no event rows ([output] event_rows = false)",
                   ctx->max_bytes, t, ctx->stats->rows, ctx->row_bytes, ctx->stats->transitions,
                   BK_TRANSITION_RECORD_BYTES, ctx->events, BK_EVENT_RECORD_BYTES);
}
