/* Probes of an island's last step, for what its root functions cannot see: a function of
 * one block evaluated on the back-end's dense output, and the zero of such a function
 * located by Brent to rounding (hidden stops, slip-rate peaks, aging breakaways). */
#include <float.h>
#include <math.h>

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

/* d|v|/dt of slipping block i for the island's vector y at t (from rest: along its mode). */
double bk_run_speed_rate(const run_island *isl, size_t i, double t, const double *y)
{
    const bk_scene *scene = isl->island.scene;
    double v = y[scene->slot[i] + 1], dir = (double)scene->mode[i];
    double accel = dir * bk_island_slip_acceleration(&isl->island, i, t, y);
    return v > 0.0 ? accel : v < 0.0 ? -accel : dir * accel;
}

/* The largest value of the cubic with values u0, u1 and slopes d0 > 0 > d1 at 0 and h. */
double bk_run_hermite_peak(double u0, double d0, double u1, double d1, double h)
{
    /* p(s) = u0 + d0 h s + c2 s^2 + c3 s^3 on s in [0, 1]. */
    double c2 = 3.0 * (u1 - u0) - (2.0 * d0 + d1) * h;
    double c3 = 2.0 * (u0 - u1) + (d0 + d1) * h;
    double a = 3.0 * c3, b = 2.0 * c2, c = d0 * h; /* p'(s) = a s^2 + b s + c */
    double s;
    if (fabs(a) < 1e-14 * (fabs(b) + fabs(c)))
        s = -c / b;
    else {
        double disc = sqrt(fmax(b * b - 4.0 * a * c, 0.0));
        /* p' > 0 at 0 and < 0 at 1: its one zero in between. */
        double q = -0.5 * (b + copysign(disc, b));
        double s1 = q / a, s2 = c / q;
        s = s1 > 0.0 && s1 < 1.0 ? s1 : s2;
    }
    s = fmin(fmax(s, 0.0), 1.0);
    return u0 + s * (d0 * h + s * (c2 + s * c3));
}

double bk_run_speed_rate_probe(double t, void *user)
{
    bk_block_probe *p = user;
    const double *y = bk_run_probe_state(p, t);
    return y ? bk_run_speed_rate(p->isl, p->block, t, y) : 0.0;
}


int bk_run_last_step(run_ctx *ctx, run_island *isl, double *lo, double *hi, const double **y)
{
    ctx->backend->last_step(isl->solver, lo, hi);
    *hi = isl->t_reached;
    *y = isl->y;
    /* A stop found inside the step ends the trajectory there. */
    if (isl->pending && isl->t_event < *hi) {
        *hi = isl->t_event;
        int rc = ctx->backend->interpolate(isl->solver, *hi, isl->y_probe, ctx->err);
        if (rc != BK_OK)
            return rc;
        *y = isl->y_probe;
    }
    if (*lo < isl->t_resume)
        *lo = isl->t_resume;
    return BK_OK;
}
