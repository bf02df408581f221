/* msbdf on stiff problems (gsl_backend.h): the derivative msbdf restarts from and the dense
 * output uses, the projection onto the slow manifold, and the evolve loop that ties them
 * to msbdf.  The right-hand side is reached through the instance's gsl_odeiv2_system. */
#include <float.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "gsl_backend.h"

/* msbdf's derivative at t_hi, f_hi, for the dense output and for msbdf's restarts: per
 * component f(t_hi, y_hi) (f_exact), but for a stiff one (h |d f_i/d y_i| > 1, from the
 * last Jacobian) p', the derivative of the polynomial through the last step ends (t_lo,
 * t_hi and up to two before them, so cubic once the start has three steps).  A stiff
 * component sits on its slow manifold only to the corrector's tolerance, and f multiplies
 * that residual by the stiffness: with rate-and-state friction, d(v')/dv = -(d F/d v +
 * damping) / m reaches 1e14-1e17 1/s at slip rates of 1e-8 m/s for m <= 1e-3 kg, so
 * f(y_hi) in the velocity row is off by m/s^2 where v itself is 1e-8 m/s (the rows' slip
 * rates came out a thousand times off).  BDF methods keep no f of their own either (their
 * Nordsieck array is the polynomial through past solution values).  Elsewhere f is the
 * better: p' is O(h^3) and msbdf runs up to order 5, so on test_solver.c's oscillator p'
 * was a hundred tolerances off where f was exact.  Step sizes within a start grow by at
 * most GSL's factor 5, so the extrapolation to t_hi stays tame. */
void bk_gsl_history_derivative(gsl_backend *b, const double *f_exact)
{
    double t[4];
    const double *y[4];
    size_t m = 0;
    for (size_t k = b->n_back; k-- > 0;) { /* oldest first */
        t[m] = b->t_back[k];
        y[m++] = b->y_back[k];
    }
    t[m] = b->t_lo;
    y[m++] = b->y_lo;
    t[m] = b->t_hi;
    y[m++] = b->y_hi;
    size_t last = m - 1;
    double w[4];
    w[last] = 0.0;
    for (size_t j = 0; j < last; ++j) {
        w[last] += 1.0 / (t[last] - t[j]);
        double c = 1.0 / (t[j] - t[last]);
        for (size_t l = 0; l < last; ++l)
            if (l != j)
                c *= (t[last] - t[l]) / (t[j] - t[l]);
        w[j] = c;
    }
    double h = b->t_hi - b->t_lo;
    for (size_t i = 0; i < b->n; ++i) {
        double d = 0.0;
        for (size_t j = 0; j < m; ++j)
            d += w[j] * y[j][i];
        b->f_hi[i] = h * b->stiffness[i] > 1.0 ? d : f_exact[i];
    }
}

/* Moves the stiff components (h |d f_i/d y_i| > 1 over the last step) of y at t back onto
 * their slow manifold, where f_i(t, y) equals the history's derivative f_lo_i: a few
 * Newton iterations on each, with its own difference quotient for d f_i/d y_i. */
static int project_stiff(gsl_backend *b, double t, double *y)
{
    size_t n = b->n;
    double h_last = b->t_lo - b->t_back[0];
    if (b->n_back == 0 || !(h_last > 0.0))
        return GSL_SUCCESS;
    double *f = b->work, *f1 = b->work2, *yp = b->y_probe;
    for (size_t i = 0; i < n; ++i) {
        if (!(h_last * b->stiffness[i] > 1.0))
            continue;
        for (int iter = 0; iter < 4; ++iter) {
            int rc = GSL_ODEIV_FN_EVAL(&b->sys, t, y, f);
            if (rc != GSL_SUCCESS)
                return rc;
            memcpy(yp, y, n * sizeof *yp);
            double inc = sqrt(DBL_EPSILON) * fmax(fabs(y[i]), b->atol[i] / b->options.rtol);
            yp[i] = y[i] + inc;
            inc = yp[i] - y[i];
            if ((rc = GSL_ODEIV_FN_EVAL(&b->sys, t, yp, f1)) != GSL_SUCCESS)
                return rc;
            double d = (f1[i] - f[i]) / inc;
            if (!(d != 0.0) || !isfinite(d))
                break;
            double delta = (f[i] - b->f_lo[i]) / d;
            y[i] -= delta;
            if (fabs(delta) <= 0.01 * (b->atol[i] + b->options.rtol * fabs(y[i])))
                break;
        }
    }
    return GSL_SUCCESS;
}

/* gsl_odeiv2_evolve_apply for msbdf (the same step-size logic: halve on a stepper failure,
 * retry at the control's smaller step on an error-test failure, stop when the step no
 * longer moves t), but the derivative handed to the stepper as dydt_in is f_lo, the
 * history's (bk_gsl_history_derivative), not f(t, y) evaluated afresh.  msbdf uses
 * dydt_in only when it (re)initialises its Nordsieck array: at the start and after it resets itself,
 * at order 1, following four rejected attempts at one t.  With f(t, y) there, the order-1
 * predictor y + h f(t, y) overshoots a stiff component by h |d f/d y| times its residual,
 * which for the rate-and-state block exceeds the tolerance for every h down to the
 * rounding of t (1/|d f/d y| ~ 1e-15 s at t ~ 100 s has no double): every attempt failed
 * and the run stopped with "step size 2.55e-15 s".  After four failures in a row, at
 * order 1 (msbdf has reset itself), the stiff components of the step's start are moved
 * back onto their slow manifold first (project_stiff): a residual left there by an
 * earlier step, which a stale Jacobian let through, is otherwise corrected in full by
 * every attempt and counted as its error (seen at 3e-5 kg, rtol 1e-6 and 1e-12). */
int bk_gsl_msbdf_evolve(gsl_backend *b, double *t, double t1, double *h)
{
    gsl_odeiv2_evolve *e = b->evolve;
    size_t n = b->n;
    double t0 = *t, h0 = *h, dt = t1 - t0;
    double *y = b->y_hi;
    memcpy(e->y0, y, n * sizeof *y);
    int failures = 0, projected = 0;
    for (;;) {
        if (failures >= 4 && !projected && gsl_odeiv2_step_order(b->stepper) == 1) {
            projected = 1;
            int rc = project_stiff(b, t0, e->y0);
            if (rc != GSL_SUCCESS)
                return rc == GSL_FAILURE ? GSL_FAILURE : GSL_EBADFUNC;
            memcpy(y, e->y0, n * sizeof *y);
            memcpy(b->y_lo, e->y0, n * sizeof *y); /* the step's dense output starts there */
        }
        int final_step = h0 >= dt;
        if (final_step)
            h0 = dt;
        int status = gsl_odeiv2_step_apply(b->stepper, t0, h0, y, e->yerr, b->f_lo, e->dydt_out, &b->sys);
        if (status == GSL_EFAULT || status == GSL_EBADFUNC)
            return status;
        if (status != GSL_SUCCESS) {
            double h_old = h0;
            h0 *= 0.5;
            if (fabs(h0) < fabs(h_old) && t0 + h0 != t0) {
                memcpy(y, e->y0, n * sizeof *y);
                e->failed_steps++;
                failures++;
                continue;
            }
            *h = h0;
            return status;
        }
        double h_old = h0;
        if (gsl_odeiv2_control_hadjust(b->control, b->stepper, y, e->yerr, e->dydt_out, &h0) ==
            GSL_ODEIV_HADJ_DEC) {
            if (fabs(h0) < fabs(h_old) && *t + h0 != *t) {
                memcpy(y, e->y0, n * sizeof *y);
                e->failed_steps++;
                failures++;
                continue;
            }
            *h = h0;
            return GSL_FAILURE;
        }
        e->count++;
        e->last_step = h_old;
        *t = final_step ? t1 : t0 + h_old;
        if (!final_step)
            *h = h0;
        return GSL_SUCCESS;
    }
}
