/* CVODE back-ends: Adams-Moulton with fixed-point iteration (non-stiff) and BDF with
 * Newton iteration and a dense or band direct linear solver (stiff).
 *
 * The run loop restarts the integrator at every transition, often with a different state
 * size (only slipping blocks are integrated); CVODE cannot change a vector's length, so a
 * size change rebuilds the CVODE objects and an equal size uses CVodeReInit. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "bksim/solver.h"
#include "sundials_jacobian.h"

/* Above this size "auto" picks the band solver (when the layout is banded). */
#define BAND_THRESHOLD 16

typedef struct cvode_backend {
    int lmm;                      /* CV_ADAMS or CV_BDF */
    bk_solver_options options;
    SUNContext ctx;
    void *cvode;
    N_Vector y, atol, work;
    SUNMatrix matrix;
    SUNLinearSolver linear_solver;
    SUNNonlinearSolver nonlinear_solver;
    size_t n;                     /* size the CVODE objects were built for */
    int n_roots;                  /* size RootInit was called with */
    bk_ode_problem problem;
    double t_stop;
    bk_solver_counters done;      /* counters of finished starts */
    char message[512];            /* last message from CVODE's error handler */
} cvode_backend;

static void capture_message(int error_code, const char *module, const char *function,
                            char *msg, void *user)
{
    cvode_backend *cv = user;
    snprintf(cv->message, sizeof cv->message, "%s (%s, code %d)", msg, function ? function : module,
             error_code);
}

static int rhs_adapter(sunrealtype t, N_Vector y, N_Vector ydot, void *user)
{
    cvode_backend *cv = user;
    return cv->problem.rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot), cv->problem.user);
}

static int roots_adapter(sunrealtype t, N_Vector y, sunrealtype *g, void *user)
{
    cvode_backend *cv = user;
    return cv->problem.roots(t, N_VGetArrayPointer(y), g, cv->problem.user);
}

static int jacobian_adapter(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix jac, void *user,
                            N_Vector tmp1, N_Vector tmp2, N_Vector tmp3)
{
    (void)fy;
    (void)tmp1;
    (void)tmp2;
    (void)tmp3;
    cvode_backend *cv = user;
    return bk_sundials_jacobian(&cv->problem, t, N_VGetArrayPointer(y), jac, 1.0, 0.0);
}

static void add_counters(cvode_backend *cv, bk_solver_counters *c)
{
    long steps = 0, rhs = 0, roots = 0, fails = 0, iters = 0;
    if (cv->cvode) {
        CVodeGetNumSteps(cv->cvode, &steps);
        CVodeGetNumRhsEvals(cv->cvode, &rhs);
        CVodeGetNumGEvals(cv->cvode, &roots);
        CVodeGetNumErrTestFails(cv->cvode, &fails);
        CVodeGetNumNonlinSolvIters(cv->cvode, &iters);
    }
    c->steps += steps;
    c->rhs_evals += rhs;
    c->root_evals += roots;
    c->err_test_fails += fails;
    c->nonlin_iters += iters;
}

static void free_objects(cvode_backend *cv)
{
    if (cv->cvode)
        CVodeFree(&cv->cvode);
    if (cv->linear_solver)
        SUNLinSolFree(cv->linear_solver);
    if (cv->matrix)
        SUNMatDestroy(cv->matrix);
    if (cv->nonlinear_solver)
        SUNNonlinSolFree(cv->nonlinear_solver);
    if (cv->y)
        N_VDestroy(cv->y);
    if (cv->atol)
        N_VDestroy(cv->atol);
    if (cv->work)
        N_VDestroy(cv->work);
    cv->cvode = NULL;
    cv->linear_solver = NULL;
    cv->matrix = NULL;
    cv->nonlinear_solver = NULL;
    cv->y = cv->atol = cv->work = NULL;
    cv->n = 0;
    cv->n_roots = -1;
}

static int fail(cvode_backend *cv, bk_error *err, const char *what, int flag)
{
    char *flag_name = CVodeGetReturnFlagName(flag); /* malloc'ed by SUNDIALS */
    BK_FAIL(err, BK_ERR_SOLVER, "CVODE: %s failed (flag %d: %s)%s%s", what, flag,
            flag_name ? flag_name : "?", cv->message[0] ? ": " : "", cv->message);
    free(flag_name);
    return BK_ERR_SOLVER;
}

static int create(void **mem, const bk_solver_options *options, int lmm, bk_error *err)
{
    cvode_backend *cv = calloc(1, sizeof *cv);
    if (!cv)
        return BK_FAIL(err, BK_ERR_NOMEM, "CVODE back-end: out of memory");
    cv->lmm = lmm;
    cv->options = *options;
    cv->n_roots = -1;
    if (SUNContext_Create(NULL, &cv->ctx) != 0) {
        free(cv);
        return BK_FAIL(err, BK_ERR_SOLVER, "CVODE back-end: SUNContext_Create failed");
    }
    *mem = cv;
    return BK_OK;
}

static int create_adams(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, CV_ADAMS, err);
}

static int create_bdf(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, CV_BDF, err);
}

static int use_band(const cvode_backend *cv, size_t n)
{
    if (strcmp(cv->options.linear_solver, "band") == 0)
        return 1;
    if (strcmp(cv->options.linear_solver, "dense") == 0)
        return 0;
    return n > BAND_THRESHOLD && 2 * cv->problem.half_bandwidth + 1 < n;
}

static int build_objects(cvode_backend *cv, size_t n, double t0, const double *y0, bk_error *err)
{
    sunindextype len = (sunindextype)n;
    cv->y = N_VNew_Serial(len, cv->ctx);
    cv->atol = N_VNew_Serial(len, cv->ctx);
    cv->work = N_VNew_Serial(len, cv->ctx);
    cv->cvode = CVodeCreate(cv->lmm, cv->ctx);
    if (!cv->y || !cv->atol || !cv->work || !cv->cvode)
        return BK_FAIL(err, BK_ERR_NOMEM, "CVODE: cannot allocate a problem of size %zu", n);
    memcpy(N_VGetArrayPointer(cv->y), y0, n * sizeof *y0);
    CVodeSetErrHandlerFn(cv->cvode, capture_message, cv);
    int flag = CVodeInit(cv->cvode, rhs_adapter, t0, cv->y);
    if (flag != CV_SUCCESS)
        return fail(cv, err, "CVodeInit", flag);
    CVodeSetUserData(cv->cvode, cv);
    CVodeSetNoInactiveRootWarn(cv->cvode);
    if (cv->lmm == CV_ADAMS) {
        cv->nonlinear_solver = SUNNonlinSol_FixedPoint(cv->y, 0, cv->ctx);
        if (!cv->nonlinear_solver)
            return BK_FAIL(err, BK_ERR_NOMEM, "CVODE: cannot create the fixed-point solver");
        flag = CVodeSetNonlinearSolver(cv->cvode, cv->nonlinear_solver);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeSetNonlinearSolver", flag);
    } else {
        if (use_band(cv, n)) {
            sunindextype bw = (sunindextype)cv->problem.half_bandwidth;
            cv->matrix = SUNBandMatrix(len, bw, bw, cv->ctx);
            cv->linear_solver = cv->matrix ? SUNLinSol_Band(cv->y, cv->matrix, cv->ctx) : NULL;
        } else {
            cv->matrix = SUNDenseMatrix(len, len, cv->ctx);
            cv->linear_solver = cv->matrix ? SUNLinSol_Dense(cv->y, cv->matrix, cv->ctx) : NULL;
        }
        if (!cv->linear_solver)
            return BK_FAIL(err, BK_ERR_NOMEM, "CVODE: cannot create the linear solver (n = %zu)", n);
        flag = CVodeSetLinearSolver(cv->cvode, cv->linear_solver, cv->matrix);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeSetLinearSolver", flag);
        if (cv->problem.jacobian && (flag = CVodeSetJacFn(cv->cvode, jacobian_adapter)) != CV_SUCCESS)
            return fail(cv, err, "CVodeSetJacFn", flag);
    }
    cv->n = n;
    return BK_OK;
}

static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    cvode_backend *cv = mem;
    cv->problem = *problem;
    cv->message[0] = '\0';
    add_counters(cv, &cv->done);
    int flag;
    if (cv->cvode && cv->n == n) {
        memcpy(N_VGetArrayPointer(cv->y), y0, n * sizeof *y0);
        flag = CVodeReInit(cv->cvode, t0, cv->y);
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
    memcpy(N_VGetArrayPointer(cv->atol), atol, n * sizeof *atol);
    if ((flag = CVodeSVtolerances(cv->cvode, cv->options.rtol, cv->atol)) != CV_SUCCESS)
        return fail(cv, err, "CVodeSVtolerances", flag);
    if ((int)problem->n_roots != cv->n_roots) {
        flag = CVodeRootInit(cv->cvode, (int)problem->n_roots, problem->n_roots ? roots_adapter : NULL);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeRootInit", flag);
        cv->n_roots = (int)problem->n_roots;
    }
    if (problem->n_roots > 0) {
        /* CVODE copies the directions; the cast only drops const from its prototype. */
        flag = CVodeSetRootDirection(cv->cvode, (int *)(uintptr_t)problem->root_direction);
        if (flag != CV_SUCCESS)
            return fail(cv, err, "CVodeSetRootDirection", flag);
    }
    if ((flag = CVodeSetStopTime(cv->cvode, t_stop)) != CV_SUCCESS)
        return fail(cv, err, "CVodeSetStopTime", flag);
    if (isfinite(cv->options.max_step) && cv->options.max_step > 0 &&
        (flag = CVodeSetMaxStep(cv->cvode, cv->options.max_step)) != CV_SUCCESS)
        return fail(cv, err, "CVodeSetMaxStep", flag);
    if (cv->options.min_step > 0 && (flag = CVodeSetMinStep(cv->cvode, cv->options.min_step)) != CV_SUCCESS)
        return fail(cv, err, "CVodeSetMinStep", flag);
    cv->t_stop = t_stop;
    return BK_OK;
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    cvode_backend *cv = mem;
    sunrealtype t = 0.0;
    int flag = CVode(cv->cvode, cv->t_stop, cv->y, &t, CV_ONE_STEP);
    *t_reached = t;
    memcpy(y, N_VGetArrayPointer(cv->y), cv->n * sizeof *y);
    switch (flag) {
    case CV_SUCCESS:
        return BK_STEP_OK;
    case CV_ROOT_RETURN:
        return BK_STEP_ROOT;
    case CV_TSTOP_RETURN:
        return BK_STEP_STOP;
    default:
        if (cv->options.min_step > 0 && strstr(cv->message, "hmin"))
            return BK_FAIL(err, BK_ERR_SOLVER,
                           "the step size fell to [solver] min_step = %g s at t = %.17g s (%s)",
                           cv->options.min_step, t, cv->message);
        return fail(cv, err, "CVode step", flag);
    }
}

static int interpolate(void *mem, double t, double *y, bk_error *err)
{
    cvode_backend *cv = mem;
    int flag = CVodeGetDky(cv->cvode, t, 0, cv->work);
    if (flag != CV_SUCCESS)
        return fail(cv, err, "CVodeGetDky", flag);
    memcpy(y, N_VGetArrayPointer(cv->work), cv->n * sizeof *y);
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
    *c = cv->done;
    add_counters(cv, c);
}

static void destroy(void *mem)
{
    cvode_backend *cv = mem;
    if (!cv)
        return;
    free_objects(cv);
    SUNContext_Free(&cv->ctx);
    free(cv);
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
};
