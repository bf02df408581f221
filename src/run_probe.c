/* Probes of an island's last step, for what its root functions cannot see: a function of
 * one block evaluated on the back-end's dense output, and the zero of such a function
 * located by Brent to rounding (hidden stops, slip-rate peaks, aging breakaways). */
#include <float.h>

#include <gsl/gsl_errno.h>

#include "run_ctx.h"

double bk_run_zero_after(run_ctx *ctx, gsl_function *f, double lo, double hi)
{
    if (gsl_root_fsolver_set(ctx->brent, f, lo, hi) != GSL_SUCCESS)
        return hi;
    for (int iter = 0; iter < 200; ++iter) {
        if (gsl_root_fsolver_iterate(ctx->brent) != GSL_SUCCESS)
            break;
        double a = gsl_root_fsolver_x_lower(ctx->brent), b = gsl_root_fsolver_x_upper(ctx->brent);
        if (gsl_root_test_interval(a, b, 0.0, 4.0 * DBL_EPSILON) == GSL_SUCCESS)
            break;
    }
    return gsl_root_fsolver_x_upper(ctx->brent);
}

const double *bk_run_probe_state(bk_block_probe *probe, double t)
{
    run_ctx *ctx = probe->ctx;
    int rc = ctx->backend->interpolate(probe->isl->solver, t, probe->isl->y_probe, ctx->err);
    if (rc != BK_OK) {
        probe->status = rc;
        return NULL;
    }
    return probe->isl->y_probe;
}
