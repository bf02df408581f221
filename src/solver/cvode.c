/* CVODE back-ends: Adams-Moulton with fixed-point iteration (non-stiff) and BDF with
 * Newton iteration and a dense or band direct linear solver (stiff).
 *
 * The run loop restarts the integrator at every transition, often with a different state
 * size (only slipping blocks are integrated); CVODE cannot change a vector's length, so a
 * size change rebuilds the CVODE objects and an equal size uses CVodeReInit. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "bksim/solver.h"
#include "sundials_common.h"
#include "sundials_jacobian.h"

typedef struct cvode_backend {
    bk_sundials_base base;        /* first: the state is its base (sundials_common.h) */
    int lmm;                      /* CV_ADAMS or CV_BDF */
    void *cvode;
    SUNNonlinearSolver nonlinear_solver;
} cvode_backend;
_Static_assert(offsetof(cvode_backend, base) == 0, "the state is allocated and freed through its base");

static int rhs_adapter(sunrealtype t, N_Vector y, N_Vector ydot, void *user)
{
    cvode_backend *cv = user;
    return cv->base.problem.rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot), cv->base.problem.user);
}

static int roots_adapter(sunrealtype t, N_Vector y, sunrealtype *g, void *user)
{
    cvode_backend *cv = user;
    return cv->base.problem.roots(t, N_VGetArrayPointer(y), g, cv->base.problem.user);
}

static int jacobian_adapter(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix jac, void *user,
                            N_Vector tmp1, N_Vector tmp2, N_Vector tmp3)
{
    (void)fy;
    (void)tmp1;
    (void)tmp2;
    (void)tmp3;
    cvode_backend *cv = user;
    return bk_sundials_jacobian(&cv->base.problem, t, N_VGetArrayPointer(y), jac, 1.0, 0.0);
}

/* The counters of the current start, as CVODE reports them. */
static bk_solver_counters this_start(const cvode_backend *cv)
{
    long steps = 0, rhs = 0, roots = 0, fails = 0, iters = 0;
    if (cv->cvode) {
        CVodeGetNumSteps(cv->cvode, &steps);
        CVodeGetNumRhsEvals(cv->cvode, &rhs);
        CVodeGetNumGEvals(cv->cvode, &roots);
        CVodeGetNumErrTestFails(cv->cvode, &fails);
        CVodeGetNumNonlinSolvIters(cv->cvode, &iters);
    }
    return (bk_solver_counters){.steps = steps, .rhs_evals = rhs, .root_evals = roots,
                                .err_test_fails = fails, .nonlin_iters = iters};
}

static void free_objects(cvode_backend *cv)
{
    if (cv->cvode)
        CVodeFree(&cv->cvode);
    if (cv->nonlinear_solver)
        SUNNonlinSolFree(cv->nonlinear_solver);
    cv->cvode = NULL;
    cv->nonlinear_solver = NULL;
    bk_sundials_free_objects(&cv->base);
}

static int fail(const cvode_backend *cv, bk_error *err, const char *what, int flag)
{
    return bk_sundials_fail(&cv->base, err, what, flag);
}

static int create(void **mem, const bk_solver_options *options, int lmm, bk_error *err)
{
    int rc = bk_sundials_create(mem, sizeof(cvode_backend), "CVODE", CVodeGetReturnFlagName, options, err);
    if (rc == BK_OK)
        ((cvode_backend *)*mem)->lmm = lmm;
    return rc;
}

static int create_adams(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, CV_ADAMS, err);
}

static int create_bdf(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, CV_BDF, err);
}

static int build_objects(cvode_backend *cv, size_t n, double t0, const double *y0, bk_error *err)
{
    bk_sundials_base *base = &cv->base;
    int rc = bk_sundials_new_vectors(base, n, err);
    if (rc != BK_OK)
        return rc;
    cv->cvode = CVodeCreate(cv->lmm, base->ctx);
    if (!cv->cvode)
        return bk_sundials_no_memory(base, n, err);
    memcpy(N_VGetArrayPointer(base->y), y0, n * sizeof *y0);
    CVodeSetErrHandlerFn(cv->cvode, bk_sundials_capture_message, base);
    int flag = CVodeInit(cv->cvode, rhs_adapter, t0, base->y);
    if (flag != CV_SUCCESS)
        return fail(cv, err, "CVodeInit", flag);
    CVodeSetUserData(cv->cvode, cv);
    CVodeSetNoInactiveRootWarn(cv->cvode);
    if (cv->lmm == CV_ADAMS) {
        cv->nonlinear_solver = SUNNonlinSol_FixedPoint(base->y, 0, base->ctx);
        if (!cv->nonlinear_solver)
            return BK_FAIL(err, BK_ERR_NOMEM, "CVODE: cannot create the fixed-point solver");
        flag = CVodeSetNonlinearSolver(cv->cvode, cv->nonlinear_solver);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeSetNonlinearSolver", flag);
    } else {
        if ((rc = bk_sundials_new_linear_solver(base, n, err)) != BK_OK)
            return rc;
        flag = CVodeSetLinearSolver(cv->cvode, base->linear_solver, base->matrix);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeSetLinearSolver", flag);
        if (base->problem.jacobian && (flag = CVodeSetJacFn(cv->cvode, jacobian_adapter)) != CV_SUCCESS)
            return fail(cv, err, "CVodeSetJacFn", flag);
    }
    base->n = n;
    return BK_OK;
}

static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    cvode_backend *cv = mem;
    bk_sundials_base *base = &cv->base;
    bk_sundials_begin_start(base, problem, this_start(cv));
    int flag;
    if (cv->cvode && base->n == n) {
        memcpy(N_VGetArrayPointer(base->y), y0, n * sizeof *y0);
        flag = CVodeReInit(cv->cvode, t0, base->y);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeReInit", flag);
    } else {
        free_objects(cv);
        int rc = build_objects(cv, n, t0, y0, err);
        if (rc != BK_OK) {
            free_objects(cv);
            return rc;
        }
    }
    memcpy(N_VGetArrayPointer(base->atol), atol, n * sizeof *atol);
    if ((flag = CVodeSVtolerances(cv->cvode, base->options.rtol, base->atol)) != CV_SUCCESS)
        return fail(cv, err, "CVodeSVtolerances", flag);
    if ((int)problem->n_roots != base->n_roots) {
        flag = CVodeRootInit(cv->cvode, (int)problem->n_roots, problem->n_roots ? roots_adapter : NULL);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeRootInit", flag);
        base->n_roots = (int)problem->n_roots;
    }
    if (problem->n_roots > 0) {
        /* CVODE copies the directions; the cast only drops const from its prototype. */
        flag = CVodeSetRootDirection(cv->cvode, (int *)(uintptr_t)problem->root_direction);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeSetRootDirection", flag);
    }
    if ((flag = CVodeSetStopTime(cv->cvode, t_stop)) != CV_SUCCESS)
        return fail(cv, err, "CVodeSetStopTime", flag);
    if (isfinite(base->options.max_step) && base->options.max_step > 0 &&
        (flag = CVodeSetMaxStep(cv->cvode, base->options.max_step)) != CV_SUCCESS)
        return fail(cv, err, "CVodeSetMaxStep", flag);
    if (base->options.min_step > 0 && (flag = CVodeSetMinStep(cv->cvode, base->options.min_step)) != CV_SUCCESS)
        return fail(cv, err, "CVodeSetMinStep", flag);
    base->t_stop = t_stop;
    return BK_OK;
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    cvode_backend *cv = mem;
    sunrealtype t = 0.0;
    int flag = CVode(cv->cvode, cv->base.t_stop, cv->base.y, &t, CV_ONE_STEP);
    *t_reached = t;
    memcpy(y, N_VGetArrayPointer(cv->base.y), cv->base.n * sizeof *y);
    switch (flag) {
    case CV_SUCCESS:
        return BK_STEP_OK;
    case CV_ROOT_RETURN:
        return BK_STEP_ROOT;
    case CV_TSTOP_RETURN:
        return BK_STEP_STOP;
    default:
        if (cv->base.options.min_step > 0 && strstr(cv->base.message, "hmin"))
            return BK_FAIL(err, BK_ERR_SOLVER,
                           "the step size fell to [solver] min_step = %g s at t = %.17g s (%s)",
                           cv->base.options.min_step, t, cv->base.message);
        return fail(cv, err, "CVode step", flag);
    }
}

static int interpolate(void *mem, double t, double *y, bk_error *err)
{
    cvode_backend *cv = mem;
    int flag = CVodeGetDky(cv->cvode, t, 0, cv->base.work);
    if (flag != CV_SUCCESS)
        return fail(cv, err, "CVodeGetDky", flag);
    memcpy(y, N_VGetArrayPointer(cv->base.work), cv->base.n * sizeof *y);
    return BK_OK;
}

static int set_stop(void *mem, double t_stop, bk_error *err)
{
    cvode_backend *cv = mem;
    int flag = CVodeSetStopTime(cv->cvode, t_stop);
    if (flag != CV_SUCCESS)
        return fail(cv, err, "CVodeSetStopTime", flag);
    cv->base.t_stop = t_stop;
    return BK_OK;
}

/* CVODE's history is a Nordsieck array: derivatives at t_n scaled by powers of the step, the
 * predictor of the next step and the dense output of the last one both being its Taylor
 * polynomial, which CVodeGetDky(t_n, k) reads term by term. */
static int predictor(void *mem, const size_t *components, size_t count, double *t_n, double *h_last,
                     double *h_next, int *order, double *coef, double *error_ratio, bk_error *err)
{
    cvode_backend *cv = mem;
    bk_sundials_base *base = &cv->base;
    sunrealtype tn = 0.0, h = 0.0, next = 0.0;
    int q = 0;
    CVodeGetCurrentTime(cv->cvode, &tn);
    CVodeGetLastStep(cv->cvode, &h);
    CVodeGetCurrentStep(cv->cvode, &next);
    CVodeGetLastOrder(cv->cvode, &q);
    long steps = 0;
    CVodeGetNumSteps(cv->cvode, &steps);
    if (steps == 0)
        q = 0; /* nothing but the start: its value only */
    const double *work = N_VGetArrayPointer(base->work);
    double factorial = 1.0;
    for (int k = 0; k <= q; ++k) {
        if (k > 0)
            factorial *= k;
        int flag = CVodeGetDky(cv->cvode, tn, k, base->work);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeGetDky", flag);
        for (size_t j = 0; j < count; ++j)
            coef[j * (BK_PREDICTOR_MAX_ORDER + 1) + (size_t)k] = work[components[j]] / factorial;
    }
    if (steps == 0) {
        for (size_t j = 0; j < count; ++j)
            error_ratio[j] = 0.0;
    } else {
        int flag = CVodeGetEstLocalErrors(cv->cvode, base->work);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeGetEstLocalErrors", flag);
        for (size_t j = 0; j < count; ++j)
            error_ratio[j] = fabs(work[components[j]]);
        if ((flag = CVodeGetErrWeights(cv->cvode, base->work)) != CV_SUCCESS)
            return fail(cv, err, "CVodeGetErrWeights", flag);
        for (size_t j = 0; j < count; ++j)
            error_ratio[j] *= work[components[j]];
    }
    *t_n = tn;
    *h_last = steps == 0 ? 0.0 : h;
    *h_next = steps == 0 ? 0.0 : next;
    *order = q;
    return BK_OK;
}

static void last_step(void *mem, double *t_lo, double *t_hi)
{
    cvode_backend *cv = mem;
    sunrealtype tn = 0.0, h = 0.0;
    CVodeGetCurrentTime(cv->cvode, &tn);
    CVodeGetLastStep(cv->cvode, &h);
    *t_hi = tn;
    *t_lo = tn - h;
}

static int root_info(void *mem, int *found)
{
    cvode_backend *cv = mem;
    return CVodeGetRootInfo(cv->cvode, found) == CV_SUCCESS ? BK_OK : BK_ERR_SOLVER;
}

static void counters(void *mem, bk_solver_counters *c)
{
    cvode_backend *cv = mem;
    bk_sundials_counters(&cv->base, this_start(cv), c);
}

static void destroy(void *mem)
{
    cvode_backend *cv = mem;
    if (!cv)
        return;
    free_objects(cv);
    bk_sundials_destroy(&cv->base);
}

const bk_solver_backend bk_solver_cvode_adams = {
    .name = "cvode_adams",
    .doc = "CVODE variable-order Adams-Moulton (orders 1-12), fixed-point iteration: non-stiff",
    .create = create_adams,
    .start = start,
    .step = step,
    .interpolate = interpolate,
    .last_step = last_step,
    .root_info = root_info,
    .counters = counters,
    .destroy = destroy,
    .set_stop = set_stop,
    .predictor = predictor,
};

const bk_solver_backend bk_solver_cvode_bdf = {
    .name = "cvode_bdf",
    .doc = "CVODE variable-order BDF (orders 1-5), Newton with dense/band direct solver: stiff",
    .create = create_bdf,
    .start = start,
    .step = step,
    .interpolate = interpolate,
    .last_step = last_step,
    .root_info = root_info,
    .counters = counters,
    .destroy = destroy,
    .set_stop = set_stop,
    .predictor = predictor,
};
