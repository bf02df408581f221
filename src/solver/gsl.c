/* GSL odeiv2 back-ends: embedded Runge-Kutta pairs (Prince-Dormand 8(7), Fehlberg 4(5))
 * and the variable-order BDF stepper msbdf (orders 1-5, Newton with GSL's dense LU on a
 * finite-difference Jacobian), with events located by bksim.
 *
 * Stepping: one gsl_odeiv2_evolve_apply per step() call (msbdf: gsl_msbdf.c's evolve, the same
 * but for the derivative msbdf restarts from) with the scaled error control,
 * D_i = atol_i + rtol |y_i| (gsl_odeiv2_control_scaled_new with eps_abs = max atol and
 * scale_abs_i = atol_i / eps_abs; msbdf: gsl_shared.c's equivalent, whose errlevel, the
 * scale of msbdf's Newton test, is D_i / sqrt(n) on stiff components, see start()).
 * GSL rejects a step when any |err_i| > 1.1 D_i: a max norm, stricter than SUNDIALS'
 * weighted RMS norm at the same rtol.  gsl_msbdf hands GSL rtol / 10 and atol / 10: GSL aims each step at the tolerance itself (SUNDIALS' BDF codes
 * aim well below it), and on the solver battery's oscillator msbdf's worst error (root
 * time, state at the root and at the stop) was 6, 18 and 32 times rtol at rtol 1e-6, 1e-8,
 * 1e-10 -- 1, 3 and 14 times with the factor, for 22, 31 and 1 % more steps.  The RK pairs
 * propagate the higher-order solution (local extrapolation) and need no factor.  max_step
 * caps every step; the stop time is reached exactly (evolve's final-step clipping is
 * always taken there).  The first step size is Hairer, Norsett & Wanner's estimate (Solving ODEs I,
 * II.4) from f at the start.
 *
 * Dense output, on [t_lo, t_hi] of the last step:
 *   gsl_rk8pd, gsl_rkf45: a fresh step of the same method from (t_lo, y_lo) of length
 *     t - t_lo (the method's own continuous extension: order 8 resp. 5, as accurate as
 *     the step; 12 resp. 5 right-hand side evaluations per call);
 *   gsl_msbdf: cubic Hermite on y and a derivative at both ends (third degree, local error
 *     O(h^4); msbdf keeps its Nordsieck history private, so its own interpolant is out of
 *     reach).  The derivative is f, but on stiff components that of the polynomial
 *     through the last step ends (gsl_msbdf.c): there f magnifies the corrector's
 *     residual by |d f/d y| (rate-and-state slip rates came out a thousand times off).
 * That is for events and merges.  Output rows (sample) come from a Hermite polynomial
 * through this and older step ends (row_nodes.h), degree 11 / 7 / 5 for rk8pd / rkf45 /
 * msbdf; an RK row whose error estimate exceeds atol_i + rtol |y_i| is re-stepped as above
 * and becomes a node (README "Output rows cost no steps").
 *
 * Events, CVODE's conventions: after each step the root functions are evaluated at its
 * end; a function whose sign changed in its allowed direction (root_direction) crossed.
 * A function exactly zero where the integration starts (or at a returned root) is
 * inactive until it is seen non-zero at a step end (at a start it is also probed just
 * past t0 along f, as CVODE does).  The earliest crossing is located on the dense output
 * with GSL's Brent solver to a bracket of 4 ulp of t; if another function already crossed
 * at the bracket's lower end, that one is located instead, on the shorter interval.
 * BK_STEP_ROOT returns the upper end of the bracket (just past the crossing) and reports
 * every function crossed by then.  A later step() first scans the rest of the step.
 *
 * Counters: rhs_evals counts every evaluation (steps, Jacobians, dense output, event
 * location); nonlin_iters is 0 (GSL does not expose msbdf's Newton iterations);
 * err_test_fails counts evolve's rejected step attempts.  linear_solver is ignored:
 * msbdf solves its Newton systems with a dense LU of its own. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <gsl/gsl_roots.h>

#include "bksim/solver.h"
#include "capacity.h"
#include "gsl_backend.h"
#include "gsl_shared.h"
#include "solver/row_nodes.h"

static const gsl_variant variant_rk8pd = {"rk8pd", &gsl_odeiv2_step_rk8pd, 8, 0, DENSE_RESTEP, 1.0, 6};
static const gsl_variant variant_rkf45 = {"rkf45", &gsl_odeiv2_step_rkf45, 5, 0, DENSE_RESTEP, 1.0, 4};
static const gsl_variant variant_msbdf = {"msbdf", &gsl_odeiv2_step_msbdf, 1, 1, DENSE_HERMITE, 0.1, 3};


/* --- callbacks ------------------------------------------------------------------------- */

static int rhs_adapter(double t, const double y[], double dydt[], void *params)
{
    gsl_backend *b = params;
    b->count.rhs_evals++;
    int rc = b->problem.rhs(t, y, dydt, b->problem.user);
    if (rc == 0)
        return GSL_SUCCESS;
    b->rhs_status = rc;
    b->rhs_fail_t = t;
    /* > 0 recoverable: evolve retries with a smaller step; < 0 aborts. */
    return rc > 0 ? GSL_FAILURE : GSL_EBADFUNC;
}

/* Forward differences, one column at a time, with CVODE's increment
 * sqrt(eps) * max(|y_j|, atol_j / rtol); dfdt the same way in t. */
static int jacobian(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
    gsl_backend *b = params;
    size_t n = b->n;
    double *f0 = b->work, *f1 = b->work2, *yp = b->y_probe;
    int rc = rhs_adapter(t, y, f0, b);
    if (rc != GSL_SUCCESS)
        return rc;
    double srur = sqrt(DBL_EPSILON);
    memcpy(yp, y, n * sizeof *yp);
    for (size_t j = 0; j < n; ++j) {
        double scale = fmax(fabs(y[j]), b->atol[j] / b->options.rtol);
        double yj = y[j];
        yp[j] = yj + srur * (scale > 0.0 ? scale : 1.0);
        double inc = yp[j] - yj;
        if ((rc = rhs_adapter(t, yp, f1, b)) != GSL_SUCCESS)
            return rc;
        for (size_t i = 0; i < n; ++i)
            dfdy[i * n + j] = (f1[i] - f0[i]) / inc;
        b->stiffness[j] = fabs(dfdy[j * n + j]);
        yp[j] = yj;
    }
    double tp = t + srur * fmax(fmax(fabs(t), fabs(b->h)), DBL_MIN / DBL_EPSILON);
    double dt = tp - t;
    if ((rc = rhs_adapter(tp, y, f1, b)) != GSL_SUCCESS)
        return rc;
    for (size_t i = 0; i < n; ++i)
        dfdt[i] = (f1[i] - f0[i]) / dt;
    return GSL_SUCCESS;
}

static int eval_roots(gsl_backend *b, double t, const double *y, double *g)
{
    b->count.root_evals++;
    int rc = b->problem.roots(t, y, g, b->problem.user);
    if (rc != 0)
        return rc;
    for (size_t i = 0; i < b->problem.n_roots; ++i)
        if (!isfinite(g[i]))
            return -1;
    return 0;
}

/* --- dense output ---------------------------------------------------------------------- */

static int dense(gsl_backend *b, double t, double *out)
{
    size_t n = b->n;
    if (t == b->t_hi) {
        memcpy(out, b->y_hi, n * sizeof *out);
        return 0;
    }
    if (t == b->t_lo) {
        memcpy(out, b->y_lo, n * sizeof *out);
        return 0;
    }
    if (b->variant->dense == DENSE_RESTEP) {
        memcpy(out, b->y_lo, n * sizeof *out);
        return gsl_odeiv2_step_apply(b->stepper, b->t_lo, t - b->t_lo, out, b->yerr, b->f_lo, NULL,
                                     &b->sys);
    }
    double h = b->t_hi - b->t_lo, s = (t - b->t_lo) / h, r = 1.0 - s;
    double h00 = (1.0 + 2.0 * s) * r * r, h10 = s * r * r * h;
    double h01 = s * s * (3.0 - 2.0 * s), h11 = -s * s * r * h;
    for (size_t i = 0; i < n; ++i)
        out[i] = h00 * b->y_lo[i] + h10 * b->f_lo[i] + h01 * b->y_hi[i] + h11 * b->f_hi[i];
    return 0;
}

/* --- events ---------------------------------------------------------------------------- */

/* Function i crossed between values g0 (non-zero) and g1 in its allowed direction; a zero
 * at the far end counts as crossed. */
static int crossed(double g0, double g1, int direction)
{
    if ((double)direction * g0 > 0.0)
        return 0; /* moving away from the allowed direction's start side */
    return g1 == 0.0 || (g0 < 0.0) != (g1 < 0.0);
}

typedef struct probe_ctx {
    gsl_backend *b;
    size_t i;
    double sign; /* +1 when function i starts positive */
} probe_ctx;

/* Function i on the dense output, oriented positive before the crossing and strictly
 * negative at and after it.  Always finite; failures go to b->status. */
static double oriented(double t, void *user)
{
    probe_ctx *p = user;
    gsl_backend *b = p->b;
    if (b->status != 0)
        return -1.0;
    int rc = dense(b, t, b->y_probe);
    if (rc == 0)
        rc = eval_roots(b, t, b->y_probe, b->g_probe);
    if (rc != 0) {
        b->status = rc;
        return -1.0;
    }
    double v = p->sign * b->g_probe[p->i];
    return v == 0.0 ? -DBL_MIN : v;
}

static int converged(double a, double c)
{
    return c - a <= 4.0 * DBL_EPSILON * fmax(fabs(a), fabs(c));
}

/* Bracket the crossing of function i in (lo, hi]: *a before it, *c at or after it. */
static void bracket(gsl_backend *b, size_t i, double lo, double hi, double *a, double *c)
{
    probe_ctx p = {b, i, b->g_scan[i] > 0.0 ? 1.0 : -1.0};
    gsl_function fn = {oriented, &p};
    *a = lo;
    *c = hi;
    double f_lo = oriented(lo, &p), f_hi = oriented(hi, &p);
    if (b->status != 0)
        return;
    if (f_lo > 0.0 && f_hi < 0.0) {
        if (!b->brent)
            b->brent = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
        gsl_root_fsolver *solver = b->brent;
        if (solver && gsl_root_fsolver_set(solver, &fn, lo, hi) == GSL_SUCCESS) {
            for (int iter = 0; iter < 100 && !converged(*a, *c); ++iter) {
                if (gsl_root_fsolver_iterate(solver) != GSL_SUCCESS || b->status != 0)
                    break;
                *a = gsl_root_fsolver_x_lower(solver);
                *c = gsl_root_fsolver_x_upper(solver);
            }
        }
        if (b->status != 0)
            return;
        /* Brent keeps a sign change, not necessarily this orientation (several zeros). */
        if (oriented(*a, &p) > 0.0 && oriented(*c, &p) < 0.0)
            return;
        *a = lo;
        *c = hi;
    }
    /* Bisection keeps "before" at a and "after" at c. */
    while (!converged(*a, *c) && b->status == 0) {
        double m = *a + 0.5 * (*c - *a);
        if (m <= *a || m >= *c)
            break;
        if (oriented(m, &p) > 0.0)
            *a = m;
        else
            *c = m;
    }
}

/* Look for crossings in (t_scan, t_hi].  Returns 1 with the earliest in t_root/y_root/found
 * (and t_scan moved there), 0 when none, < 0 on failure. */
static int scan(gsl_backend *b, double *t_root)
{
    size_t m = b->problem.n_roots;
    const int *dir = b->problem.root_direction;
    double *g_right = b->g_root; /* values at t_right */
    memcpy(g_right, b->g_hi, m * sizeof *g_right);
    double t_right = b->t_hi;
    for (;;) {
        /* The function that crossed in (t_scan, t_right] furthest from its end, as CVODE
         * picks: linearly, the earliest. */
        size_t pick = m;
        double best = -1.0;
        for (size_t i = 0; i < m; ++i) {
            if (!b->active[i] || !crossed(b->g_scan[i], g_right[i], dir[i]))
                continue;
            double frac = fabs(g_right[i] / (g_right[i] - b->g_scan[i]));
            if (frac > best) {
                best = frac;
                pick = i;
            }
        }
        if (pick == m)
            return 0;
        double a, c;
        bracket(b, pick, b->t_scan, t_right, &a, &c);
        if (b->status != 0)
            return b->status < 0 ? b->status : -b->status;
        /* Did another function cross before a? Then that one comes first. */
        double *g_a = b->g_probe;
        int rc = dense(b, a, b->y_probe);
        if (rc == 0 && a != b->t_scan)
            rc = eval_roots(b, a, b->y_probe, g_a);
        if (rc != 0)
            return rc < 0 ? rc : -rc;
        int earlier = 0;
        if (a != b->t_scan)
            for (size_t j = 0; j < m && !earlier; ++j)
                earlier = b->active[j] && crossed(b->g_scan[j], g_a[j], dir[j]);
        if (earlier) {
            t_right = a;
            memcpy(g_right, g_a, m * sizeof *g_right);
            continue;
        }
        /* The root: at c, just past the crossing. */
        if ((rc = dense(b, c, b->y_root)) != 0 || (rc = eval_roots(b, c, b->y_root, g_right)) != 0)
            return rc < 0 ? rc : -rc;
        for (size_t j = 0; j < m; ++j) {
            b->found[j] = 0;
            if (b->active[j] && crossed(b->g_scan[j], g_right[j], dir[j]))
                b->found[j] = b->g_scan[j] > 0.0 ? -1 : +1;
        }
        b->found[pick] = b->g_scan[pick] > 0.0 ? -1 : +1;
        /* Resume past the root; a function sitting exactly on zero there waits. */
        for (size_t j = 0; j < m; ++j) {
            b->g_scan[j] = g_right[j];
            if (g_right[j] == 0.0)
                b->active[j] = 0;
        }
        b->t_scan = c;
        *t_root = c;
        return 1;
    }
}

/* No root left in the step: the step end becomes the scan start; functions seen non-zero
 * there come alive. */
static void finish_step(gsl_backend *b)
{
    for (size_t j = 0; j < b->problem.n_roots; ++j) {
        b->g_scan[j] = b->g_hi[j];
        if (!b->active[j] && b->g_hi[j] != 0.0)
            b->active[j] = 1;
    }
    b->t_scan = b->t_hi;
    b->pending = 0;
}

/* --- set-up ---------------------------------------------------------------------------- */

static void free_steppers(gsl_backend *b)
{
    if (b->driver)
        gsl_odeiv2_driver_free(b->driver);
    bk_gsl_shared_release(b->shared);
    b->driver = NULL;
    b->shared = NULL;
    b->stepper = NULL;
    b->evolve = NULL;
    b->control = NULL;
    b->driver_n = 0;
}

static void free_arrays(gsl_backend *b)
{
    free(b->arena);
    free(b->active);
    b->arena = NULL;
    b->active = b->found = NULL;
    b->capacity = b->root_capacity = 0;
}

/* Every array of the instance in one block, laid out in the order a step visits them: a long
 * chain runs thousands of islands in turn, each with its own instance, and scattered small
 * blocks cost a cache miss each at every turn. */
static int reserve(gsl_backend *b, size_t n, size_t m)
{
    int n_fits = bk_capacity_fits(n, b->capacity), m_fits = bk_capacity_fits(m, b->root_capacity);
    if (n_fits && m_fits)
        return 0;
    size_t cap_n = n_fits ? b->capacity : n, cap_m = m_fits ? b->root_capacity : m;
    double *arena = malloc((14 * cap_n + 4 * cap_m + 1) * sizeof *arena);
    int *flags = malloc((2 * cap_m + 1) * sizeof *flags);
    if (!arena || !flags) {
        free(arena);
        free(flags);
        return -1;
    }
    double **arrays[] = {&b->y_lo, &b->f_lo, &b->y_hi, &b->f_hi, &b->y_root, &b->y_probe,
                         &b->atol, &b->scale, &b->work, &b->work2, &b->yerr,
                         &b->y_back[0], &b->y_back[1], &b->stiffness};
    double **roots[] = {&b->g_scan, &b->g_hi, &b->g_probe, &b->g_root};
    double *next = arena;
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; ++k, next += cap_n)
        *arrays[k] = next;
    for (size_t k = 0; k < sizeof roots / sizeof *roots; ++k, next += cap_m)
        *roots[k] = next;
    /* Nothing carries over: a start fills what it needs (msbdf's driver is made anew, as
     * the weights it was made for are gone). */
    free_steppers(b);
    free(b->arena);
    free(b->active);
    b->arena = arena;
    b->active = flags;
    b->found = flags + cap_m;
    b->capacity = cap_n;
    b->root_capacity = cap_m;
    return 0;
}

static int create(void **mem, const bk_solver_options *options, const gsl_variant *variant,
                  bk_error *err)
{
    gsl_backend *b = calloc(1, sizeof *b);
    if (!b)
        return BK_FAIL(err, BK_ERR_NOMEM, "GSL back-end: out of memory");
    b->variant = variant;
    b->options = *options;
    b->max_step = isfinite(options->max_step) && options->max_step > 0.0 ? options->max_step : INFINITY;
    *mem = b;
    return BK_OK;
}

static int create_rk8pd(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, &variant_rk8pd, err);
}

static int create_rkf45(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, &variant_rkf45, err);
}

static int create_msbdf(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, &variant_msbdf, err);
}

/* Weighted RMS norm with CVODE's weights 1 / (atol + rtol |y0|). */
static double wrms(const gsl_backend *b, const double *v, const double *y0)
{
    double sum = 0.0;
    for (size_t i = 0; i < b->n; ++i) {
        double w = v[i] / (b->atol[i] + b->options.rtol * fabs(y0[i]));
        sum += w * w;
    }
    return sqrt(sum / (double)b->n);
}

/* Hairer, Norsett & Wanner's starting step (Solving ODEs I, II.4), capped. */
static int initial_step(gsl_backend *b, double t0, double span, double *h)
{
    double d0 = wrms(b, b->y_hi, b->y_hi), d1 = wrms(b, b->f_hi, b->y_hi);
    double h0 = d0 < 1e-5 || d1 < 1e-5 ? 1e-6 * span : 0.01 * d0 / d1;
    h0 = fmin(h0, span);
    for (size_t i = 0; i < b->n; ++i)
        b->y_probe[i] = b->y_hi[i] + h0 * b->f_hi[i];
    int rc = rhs_adapter(t0 + h0, b->y_probe, b->work, b);
    if (rc == GSL_FAILURE) { /* recoverable: start small, evolve shrinks further if needed */
        b->rhs_status = 0;
        *h = fmin(h0, b->max_step);
        return GSL_SUCCESS;
    }
    if (rc != GSL_SUCCESS)
        return rc;
    for (size_t i = 0; i < b->n; ++i)
        b->work2[i] = (b->work[i] - b->f_hi[i]) / h0;
    double d2 = wrms(b, b->work2, b->y_hi), d = fmax(d1, d2);
    double h1 = d <= 1e-15 ? fmax(1e-6 * span, 1e-3 * h0)
                           : pow(0.01 / d, 1.0 / (double)(b->variant->order + 1));
    *h = fmin(fmin(100.0 * h0, h1), fmin(span, b->max_step));
    return GSL_SUCCESS;
}

static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    gsl_backend *b = mem;
    b->problem = *problem;
    b->status = 0;
    b->rhs_status = 0;
    if (n == 0)
        return BK_FAIL(err, BK_ERR_SOLVER, "GSL: empty problem");
    if (reserve(b, n, problem->n_roots) != 0)
        return BK_FAIL(err, BK_ERR_NOMEM, "GSL: cannot allocate a problem of size %zu", n);
    b->n = n;
    b->sys = (gsl_odeiv2_system){rhs_adapter, b->variant->needs_jacobian ? jacobian : NULL, n, b};
    memcpy(b->atol, atol, n * sizeof *atol);
    memcpy(b->y_hi, y0, n * sizeof *y0);
    memcpy(b->y_lo, y0, n * sizeof *y0);
    b->t_lo = b->t_hi = b->t_scan = t0;
    b->n_back = 0;
    memset(b->stiffness, 0, n * sizeof *b->stiffness);
    b->t_stop = t_stop;
    b->stepped = b->pending = 0;
    /* Kept from the start, rows or not: a row's polynomial must not depend on when the
     * first row came (a restarted run writes the same rows as an uninterrupted one). */
    if (bk_row_nodes_start(&b->rows, n) != 0)
        return BK_FAIL(err, BK_ERR_NOMEM, "GSL %s: out of memory for dense output (n = %zu)",
                       b->variant->label, n);
    int rc = rhs_adapter(t0, y0, b->f_hi, b);
    double span = t_stop - t0;
    b->h = 0.0;
    if (rc == GSL_SUCCESS && span > 0.0)
        rc = initial_step(b, t0, span, &b->h);
    if (rc != GSL_SUCCESS)
        return BK_FAIL(err, BK_ERR_SOLVER, "GSL %s: the right-hand side failed at t = %.17g s (%d)",
                       b->variant->label, b->rhs_fail_t, b->rhs_status);
    memcpy(b->f_lo, b->f_hi, n * sizeof *b->f_hi);

    /* The control's D_i = eps_abs * scale_i + rtol |y_i| = atol_i + rtol |y_i|. */
    double eps_abs = 0.0;
    for (size_t i = 0; i < n; ++i)
        eps_abs = fmax(eps_abs, atol[i]);
    for (size_t i = 0; i < n; ++i)
        b->work[i] = eps_abs > 0.0 ? atol[i] / eps_abs : 0.0;
    double factor = b->variant->tolerance_factor;
    if (b->variant->dense == DENSE_RESTEP) {
        if (!b->shared || b->shared->n != n) {
            free_steppers(b);
            b->shared = bk_gsl_shared_acquire(*b->variant->type, n);
            if (b->shared) {
                b->stepper = b->shared->stepper;
                b->evolve = b->shared->evolve;
                b->control = b->shared->control;
            }
        }
    } else if (b->driver && b->driver_n == n && eps_abs == b->eps_abs &&
               memcmp(b->work, b->scale, n * sizeof *b->work) == 0) {
        /* The tolerances the driver was made for (its control copied the weights): reset
         * rather than allocate anew, as an island restarts at every event.  Reset, the
         * objects start exactly as new ones do. */
        gsl_odeiv2_driver_reset(b->driver);
        gsl_odeiv2_driver_reset_hstart(b->driver, b->h > 0.0 ? b->h : 1.0);
    } else {
        free_steppers(b);
        b->driver = gsl_odeiv2_driver_alloc_scaled_new(&b->sys, *b->variant->type, b->h > 0.0 ? b->h : 1.0,
                                                       factor * eps_abs, factor * b->options.rtol,
                                                       1.0, 0.0, b->work);
        /* The driver's control replaced by bksim's (the same error test) whose errlevel, the
         * scale of msbdf's Newton test, is D_i / sqrt(n) for a stiff component (h |d f_i/
         * d y_i| > 1, from the last Jacobian: b->stiffness): msbdf tests its corrections
         * in the RMS norm over the n components, the error test takes the largest.  A
         * stiff component's Newton residual is not damped by the next step but comes back
         * whole in its correction, the error estimate: with the RMS test a residual on the
         * slip rate alone passed at sqrt(n) times what the error test allows, the next
         * steps failed on it, msbdf reset itself and (see gsl_msbdf.c) could not restart.
         * Non-stiff components keep D_i (their residual is damped by h |d f/d y| < 1; at
         * 1/sqrt(n) for all, test_solver.c's oscillator took 30 % more steps). */
        gsl_odeiv2_control *own = b->driver ? bk_gsl_control_alloc() : NULL;
        if (b->driver && !own) {
            free_steppers(b);
        } else if (own) {
            gsl_odeiv2_control_free(b->driver->c);
            b->driver->c = own;
            bk_gsl_control_weights(own, factor * eps_abs, factor * b->options.rtol, b->scale);
            bk_gsl_control_stiff_errlevel(own, b->stiffness, 1.0 / sqrt((double)n));
        }
        if (b->driver) {
            b->stepper = b->driver->s;
            b->evolve = b->driver->e;
            b->control = b->driver->c;
            b->driver_n = n;
        }
    }
    if (!b->stepper) {
        free_steppers(b);
        return BK_FAIL(err, BK_ERR_NOMEM, "GSL %s: cannot allocate the stepper (n = %zu)",
                       b->variant->label, n);
    }
    memcpy(b->scale, b->work, n * sizeof *b->work);
    b->eps_abs = eps_abs;

    /* Roots: functions exactly zero at t0 wait until they are not; probe them just past
     * t0 along f, as CVODE does. */
    size_t m = problem->n_roots;
    if (m > 0) {
        if (eval_roots(b, t0, y0, b->g_scan) != 0)
            return BK_FAIL(err, BK_ERR_SOLVER, "GSL %s: the root functions failed at t = %.17g s",
                           b->variant->label, t0);
        int any_zero = 0;
        for (size_t j = 0; j < m; ++j) {
            b->active[j] = b->g_scan[j] != 0.0;
            any_zero |= !b->active[j];
        }
        if (any_zero && span > 0.0) {
            double dt = fmin(100.0 * DBL_EPSILON * (fabs(t0) + fabs(b->h)), 0.5 * span);
            for (size_t i = 0; i < n; ++i)
                b->y_probe[i] = y0[i] + dt * b->f_hi[i];
            if (eval_roots(b, t0 + dt, b->y_probe, b->g_probe) != 0)
                return BK_FAIL(err, BK_ERR_SOLVER, "GSL %s: the root functions failed at t = %.17g s",
                               b->variant->label, t0 + dt);
            for (size_t j = 0; j < m; ++j)
                if (!b->active[j] && b->g_probe[j] != 0.0) {
                    b->active[j] = 1;
                    b->g_scan[j] = b->g_probe[j];
                }
        }
    }
    return BK_OK;
}

/* --- stepping -------------------------------------------------------------------------- */

static int step_failed(gsl_backend *b, int status, double t, bk_error *err)
{
    if (b->status != 0)
        return BK_FAIL(err, BK_ERR_SOLVER, "GSL %s: dense output or root functions failed near t = %.17g s (%d)",
                       b->variant->label, t, b->status);
    if (status == GSL_EBADFUNC || b->rhs_status < 0)
        return BK_FAIL(err, BK_ERR_SOLVER, "GSL %s: the right-hand side failed at t = %.17g s (%d)",
                       b->variant->label, b->rhs_fail_t, b->rhs_status);
    return BK_FAIL(err, BK_ERR_SOLVER,
                   "GSL %s: step failed at t = %.17g s (status %d: %s; step size %.3g s)%s",
                   b->variant->label, t, status, gsl_strerror(status), b->h,
                   b->rhs_status > 0 ? "; the right-hand side kept failing" : "");
}

static int root_return(gsl_backend *b, double t_root, double *t_reached, double *y)
{
    b->pending = 1;
    *t_reached = t_root;
    memcpy(y, b->y_root, b->n * sizeof *y);
    return BK_STEP_ROOT;
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    gsl_backend *b = mem;
    size_t n = b->n, m = b->problem.n_roots;
    double t_root;
    int rc;
    if (b->pending) {
        if ((rc = scan(b, &t_root)) < 0)
            return step_failed(b, rc, b->t_scan, err);
        if (rc == 1)
            return root_return(b, t_root, t_reached, y);
        finish_step(b);
    }
    if (b->t_hi >= b->t_stop) {
        *t_reached = b->t_hi;
        memcpy(y, b->y_hi, n * sizeof *y);
        return BK_STEP_STOP;
    }

    /* One step from the end of the last. */
    if (b->t_hi > b->t_lo) {
        bk_row_nodes_push(&b->rows, b->t_lo, b->y_lo, b->f_lo);
        if (b->driver) { /* msbdf: t_lo joins the step ends bk_gsl_history_derivative reads */
            double *oldest = b->y_back[1];
            b->y_back[1] = b->y_back[0];
            b->t_back[1] = b->t_back[0];
            b->y_back[0] = oldest;
            b->t_back[0] = b->t_lo;
            memcpy(oldest, b->y_lo, n * sizeof *y);
            if (b->n_back < 2)
                b->n_back++;
        }
    }
    memcpy(b->y_lo, b->y_hi, n * sizeof *y);
    memcpy(b->f_lo, b->f_hi, n * sizeof *y);
    b->t_lo = b->t_hi;
    double t = b->t_lo, remaining = b->t_stop - t;
    double h = fmin(b->h, b->max_step);
    /* Over-ask at the end so that evolve takes its final-step branch, which lands on
     * t_stop exactly and leaves the suggested step alone. */
    double h_in = h >= remaining ? 2.0 * remaining : h;
    gsl_odeiv2_evolve *e = b->evolve;
    if (b->shared) {
        bk_gsl_control_weights(b->control, b->variant->tolerance_factor * b->eps_abs,
                               b->variant->tolerance_factor * b->options.rtol, b->scale);
        /* What evolve would reuse as the step's initial derivative: f at its start. */
        memcpy(e->dydt_out, b->f_lo, n * sizeof *y);
        e->count = 1;
    }
    unsigned long failed = e->failed_steps;
    b->rhs_status = 0;
    int status = b->driver ? bk_gsl_msbdf_evolve(b, &t, b->t_stop, &h_in)
                           : gsl_odeiv2_evolve_apply(e, b->control, b->stepper, &b->sys, &t, b->t_stop, &h_in,
                                                     b->y_hi);
    b->count.err_test_fails += (long)(e->failed_steps - failed);
    if (status != GSL_SUCCESS) {
        memcpy(b->y_hi, b->y_lo, n * sizeof *y);
        b->t_hi = b->t_lo;
        b->h = h_in; /* the step size that failed, for the message */
        return step_failed(b, status, b->t_lo, err);
    }
    if (t != b->t_stop)
        b->h = h_in;
    b->t_hi = t;
    b->stepped = 1;
    b->count.steps++;
    if (b->driver) {
        bk_gsl_history_derivative(b, e->dydt_out);
    } else if (b->stepper->type->gives_exact_dydt_out) {
        memcpy(b->f_hi, e->dydt_out, n * sizeof *y);
    } else if (rhs_adapter(t, b->y_hi, b->f_hi, b) != GSL_SUCCESS) {
        return step_failed(b, GSL_EBADFUNC, t, err);
    }

    if (m > 0) {
        if (eval_roots(b, t, b->y_hi, b->g_hi) != 0)
            return BK_FAIL(err, BK_ERR_SOLVER, "GSL %s: the root functions failed at t = %.17g s",
                           b->variant->label, t);
        b->t_scan = b->t_lo;
        if ((rc = scan(b, &t_root)) < 0)
            return step_failed(b, rc, b->t_lo, err);
        if (rc == 1)
            return root_return(b, t_root, t_reached, y);
    }
    finish_step(b);
    *t_reached = t;
    memcpy(y, b->y_hi, n * sizeof *y);
    return t >= b->t_stop ? BK_STEP_STOP : BK_STEP_OK;
}

static int interpolate(void *mem, double t, double *y, bk_error *err)
{
    gsl_backend *b = mem;
    double fuzz = 100.0 * DBL_EPSILON * (fabs(b->t_lo) + fabs(b->t_hi));
    if (!(t >= b->t_lo - fuzz && t <= b->t_hi + fuzz))
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "GSL %s: dense output at t = %.17g s outside the last step [%.17g, %.17g]",
                       b->variant->label, t, b->t_lo, b->t_hi);
    b->rhs_status = 0;
    if (dense(b, t, y) != 0)
        return BK_FAIL(err, BK_ERR_SOLVER, "GSL %s: dense output failed at t = %.17g s (%d)",
                       b->variant->label, t, b->rhs_status);
    return BK_OK;
}

/* Rows from the Hermite polynomial when the last node's share of it (the error estimate)
 * is within the tolerance, atol_i + rtol |y_i|, in every component; else (RK) from a fresh
 * step from the step's start, which becomes a node, so a step needs few of them. */
static int sample(void *mem, double t, double *y, bk_error *err)
{
    gsl_backend *b = mem;
    if (t == b->t_hi || t == b->t_lo || !(t > b->t_lo && t < b->t_hi)) {
        /* The ends are exact; outside the step, interpolate says what is wrong. */
        return interpolate(mem, t, y, err);
    }
    bk_row_nodes *rows = &b->rows;
    bk_row_nodes_prepare(rows, b->variant->sample_nodes, b->t_lo, b->y_lo, b->f_lo, b->t_hi, b->y_hi,
                         b->f_hi);
    double *tail = b->work2;
    bk_hermite_eval(&rows->poly, t, y, tail);
    if (b->variant->dense != DENSE_RESTEP)
        return BK_OK;
    size_t i = 0;
    while (i < b->n && fabs(tail[i]) <= b->atol[i] + b->options.rtol * fabs(y[i]))
        ++i;
    if (i == b->n)
        return BK_OK;
    /* A fresh step from the step's start (the method's own accuracy), and f at its end:
     * a node inside the step while there is room. */
    double *y_node = y, *f_node = NULL;
    int keep = bk_row_nodes_inner(rows, &y_node, &f_node);
    memcpy(y_node, b->y_lo, b->n * sizeof *y_node);
    b->rhs_status = 0;
    if (gsl_odeiv2_step_apply(b->stepper, b->t_lo, t - b->t_lo, y_node, b->yerr, b->f_lo, f_node,
                              &b->sys) != GSL_SUCCESS)
        return BK_FAIL(err, BK_ERR_SOLVER, "GSL %s: dense output failed at t = %.17g s (%d)",
                       b->variant->label, t, b->rhs_status);
    if (keep) {
        memcpy(y, y_node, b->n * sizeof *y);
        bk_row_nodes_add_inner(rows, t);
    }
    return BK_OK;
}

static void last_step(void *mem, double *t_lo, double *t_hi)
{
    gsl_backend *b = mem;
    *t_lo = b->t_lo;
    *t_hi = b->t_hi;
}

static int root_info(void *mem, int *found)
{
    gsl_backend *b = mem;
    if (!b->pending)
        return BK_ERR_SOLVER;
    memcpy(found, b->found, b->problem.n_roots * sizeof *found);
    return BK_OK;
}

static void counters(void *mem, bk_solver_counters *c)
{
    gsl_backend *b = mem;
    *c = b->count;
}

static void destroy(void *mem)
{
    gsl_backend *b = mem;
    if (!b)
        return;
    free_steppers(b);
    gsl_root_fsolver_free(b->brent);
    free_arrays(b);
    bk_row_nodes_free(&b->rows);
    free(b);
}

#define GSL_BACKEND(NAME, CREATE, DOC)                                                          \
    {                                                                                           \
        .name = NAME, .doc = DOC, .create = CREATE, .start = start, .step = step,               \
        .interpolate = interpolate, .sample = sample, .last_step = last_step,                   \
        .root_info = root_info, .counters = counters, .destroy = destroy,                       \
    }

const bk_solver_backend bk_solver_gsl_rk8pd = GSL_BACKEND(
    "gsl_rk8pd", create_rk8pd,
    "GSL explicit Prince-Dormand 8(7), 13 stages, events located by bksim: non-stiff, tight "
    "tolerances");
const bk_solver_backend bk_solver_gsl_rkf45 = GSL_BACKEND(
    "gsl_rkf45", create_rkf45,
    "GSL explicit Runge-Kutta-Fehlberg 4(5), 6 stages, events located by bksim: non-stiff");
const bk_solver_backend bk_solver_gsl_msbdf = GSL_BACKEND(
    "gsl_msbdf", create_msbdf,
    "GSL variable-order BDF (orders 1-5), Newton with a dense LU on a difference-quotient "
    "Jacobian, events located by bksim: stiff");
