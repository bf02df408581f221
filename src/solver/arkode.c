/* ARKODE ARKStep back-ends: explicit Runge-Kutta pairs with a chosen Butcher table
 * (Bogacki-Shampine 3(2) as in MATLAB's ode23, Dormand-Prince 5(4) as in ode45, ARKODE's
 * default order-4 pair), a diagonally implicit method and an additive (IMEX) pair, the last
 * two with Newton iteration and a dense or band direct linear solver.
 *
 * IMEX split: the compact ODE the run loop hands over has no part that is known to be
 * non-stiff (the springs, the friction state relaxation and the rate-dependent friction
 * all enter the same components), and the interface does not expose one.  arkode_imex
 * therefore treats the whole right-hand side implicitly and gives the explicit tableau a
 * right-hand side that is identically zero: it runs the implicit (ESDIRK) half of
 * Kennedy & Carpenter's ARK4(3)6L[2]SA pair with that pair's embedding, which differs from
 * arkode_dirk only in the tableau.  It is a hook for a real split, not one.
 *
 * Dense output and root finding are ARKODE's own (Hermite interpolation of the step,
 * roots located on it); the state returned at a root is at ARKODE's upper bracket, just
 * past the crossing, as with CVODE.  Like cvode.c, a restart of equal size reinitialises
 * and a size change rebuilds every object.
 *
 * rhs_evals counts fe + fi evaluations plus those ARKODE makes for difference-quotient
 * Jacobians (ARKStepGetNumLinRhsEvals); for arkode_imex the fe count is of the zero
 * function. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "bksim/solver.h"
#include "sundials_jacobian.h"

/* Above this size "auto" picks the band solver (when the layout is banded); as cvode.c. */
#define BAND_THRESHOLD 16

typedef enum { KIND_EXPLICIT, KIND_IMPLICIT, KIND_IMEX } ark_kind;

typedef struct ark_variant {
    ark_kind kind;
    ARKODE_ERKTableID erk;
    ARKODE_DIRKTableID dirk;
} ark_variant;

static const ark_variant variant_bs23 = {KIND_EXPLICIT, ARKODE_BOGACKI_SHAMPINE_4_2_3, ARKODE_DIRK_NONE};
static const ark_variant variant_dp45 = {KIND_EXPLICIT, ARKODE_DORMAND_PRINCE_7_4_5, ARKODE_DIRK_NONE};
static const ark_variant variant_erk = {KIND_EXPLICIT, ARKODE_ZONNEVELD_5_3_4, ARKODE_DIRK_NONE};
static const ark_variant variant_dirk = {KIND_IMPLICIT, ARKODE_ERK_NONE, ARKODE_SDIRK_5_3_4};
static const ark_variant variant_imex = {KIND_IMEX, ARKODE_ARK436L2SA_ERK_6_3_4, ARKODE_ARK436L2SA_DIRK_6_3_4};

typedef struct arkode_backend {
    ark_variant variant;
    bk_solver_options options;
    SUNContext ctx;
    void *arkode;
    N_Vector y, atol, work;
    SUNMatrix matrix;
    SUNLinearSolver linear_solver;
    size_t n;                     /* size the ARKODE objects were built for */
    int n_roots;                  /* size RootInit was called with */
    bk_ode_problem problem;
    double t_stop;
    bk_solver_counters done;      /* counters of finished starts */
    char message[512];            /* last message from ARKODE's error handler */
} arkode_backend;

static void capture_message(int error_code, const char *module, const char *function,
                            char *msg, void *user)
{
    arkode_backend *ark = user;
    snprintf(ark->message, sizeof ark->message, "%s (%s, code %d)", msg,
             function ? function : module, error_code);
}

static int rhs_adapter(sunrealtype t, N_Vector y, N_Vector ydot, void *user)
{
    arkode_backend *ark = user;
    return ark->problem.rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot), ark->problem.user);
}

/* The explicit half of arkode_imex: nothing is treated explicitly (see the top). */
static int zero_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void *user)
{
    (void)t;
    (void)y;
    (void)user;
    N_VConst(0.0, ydot);
    return 0;
}

static int roots_adapter(sunrealtype t, N_Vector y, sunrealtype *g, void *user)
{
    arkode_backend *ark = user;
    return ark->problem.roots(t, N_VGetArrayPointer(y), g, ark->problem.user);
}

static ARKRhsFn explicit_fn(const arkode_backend *ark)
{
    switch (ark->variant.kind) {
    case KIND_EXPLICIT:
        return rhs_adapter;
    case KIND_IMEX:
        return zero_rhs;
    default:
        return NULL;
    }
}

static ARKRhsFn implicit_fn(const arkode_backend *ark)
{
    return ark->variant.kind == KIND_EXPLICIT ? NULL : rhs_adapter;
}

static void add_counters(arkode_backend *ark, bk_solver_counters *c)
{
    long steps = 0, fe = 0, fi = 0, fls = 0, roots = 0, fails = 0, iters = 0;
    if (ark->arkode) {
        ARKStepGetNumSteps(ark->arkode, &steps);
        ARKStepGetNumRhsEvals(ark->arkode, &fe, &fi);
        ARKStepGetNumGEvals(ark->arkode, &roots);
        ARKStepGetNumErrTestFails(ark->arkode, &fails);
        if (ark->variant.kind != KIND_EXPLICIT) {
            ARKStepGetNumNonlinSolvIters(ark->arkode, &iters);
            ARKStepGetNumLinRhsEvals(ark->arkode, &fls);
        }
    }
    c->steps += steps;
    c->rhs_evals += fe + fi + fls;
    c->root_evals += roots;
    c->err_test_fails += fails;
    c->nonlin_iters += iters;
}

static void free_objects(arkode_backend *ark)
{
    if (ark->arkode)
        ARKStepFree(&ark->arkode);
    if (ark->linear_solver)
        SUNLinSolFree(ark->linear_solver);
    if (ark->matrix)
        SUNMatDestroy(ark->matrix);
    if (ark->y)
        N_VDestroy(ark->y);
    if (ark->atol)
        N_VDestroy(ark->atol);
    if (ark->work)
        N_VDestroy(ark->work);
    ark->arkode = NULL;
    ark->linear_solver = NULL;
    ark->matrix = NULL;
    ark->y = ark->atol = ark->work = NULL;
    ark->n = 0;
    ark->n_roots = -1;
}

static int fail(arkode_backend *ark, bk_error *err, const char *what, int flag)
{
    char *flag_name = ARKStepGetReturnFlagName(flag); /* malloc'ed by SUNDIALS */
    BK_FAIL(err, BK_ERR_SOLVER, "ARKODE: %s failed (flag %d: %s)%s%s", what, flag,
            flag_name ? flag_name : "?", ark->message[0] ? ": " : "", ark->message);
    free(flag_name);
    return BK_ERR_SOLVER;
}

/* The problem's exact Jacobian (the implicit part is the whole right-hand side). */
static int jacobian_adapter(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix jac, void *user,
                            N_Vector tmp1, N_Vector tmp2, N_Vector tmp3)
{
    (void)fy;
    (void)tmp1;
    (void)tmp2;
    (void)tmp3;
    arkode_backend *ark = user;
    return bk_sundials_jacobian(&ark->problem, t, N_VGetArrayPointer(y), jac, 1.0, 0.0);
}

static int create(void **mem, const bk_solver_options *options, const ark_variant *variant,
                  bk_error *err)
{
    arkode_backend *ark = calloc(1, sizeof *ark);
    if (!ark)
        return BK_FAIL(err, BK_ERR_NOMEM, "ARKODE back-end: out of memory");
    ark->variant = *variant;
    ark->options = *options;
    ark->n_roots = -1;
    if (SUNContext_Create(NULL, &ark->ctx) != 0) {
        free(ark);
        return BK_FAIL(err, BK_ERR_SOLVER, "ARKODE back-end: SUNContext_Create failed");
    }
    *mem = ark;
    return BK_OK;
}

static int create_bs23(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, &variant_bs23, err);
}

static int create_dp45(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, &variant_dp45, err);
}

static int create_erk(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, &variant_erk, err);
}

static int create_dirk(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, &variant_dirk, err);
}

static int create_imex(void **mem, const bk_solver_options *options, bk_error *err)
{
    return create(mem, options, &variant_imex, err);
}

static int use_band(const arkode_backend *ark, size_t n)
{
    if (strcmp(ark->options.linear_solver, "band") == 0)
        return 1;
    if (strcmp(ark->options.linear_solver, "dense") == 0)
        return 0;
    return n > BAND_THRESHOLD && 2 * ark->problem.half_bandwidth + 1 < n;
}

static int build_objects(arkode_backend *ark, size_t n, double t0, const double *y0, bk_error *err)
{
    sunindextype len = (sunindextype)n;
    ark->y = N_VNew_Serial(len, ark->ctx);
    ark->atol = N_VNew_Serial(len, ark->ctx);
    ark->work = N_VNew_Serial(len, ark->ctx);
    if (!ark->y || !ark->atol || !ark->work)
        return BK_FAIL(err, BK_ERR_NOMEM, "ARKODE: cannot allocate a problem of size %zu", n);
    memcpy(N_VGetArrayPointer(ark->y), y0, n * sizeof *y0);
    ark->arkode = ARKStepCreate(explicit_fn(ark), implicit_fn(ark), t0, ark->y, ark->ctx);
    if (!ark->arkode)
        return BK_FAIL(err, BK_ERR_NOMEM, "ARKODE: ARKStepCreate failed (size %zu)", n);
    ARKStepSetErrHandlerFn(ark->arkode, capture_message, ark);
    ARKStepSetUserData(ark->arkode, ark);
    ARKStepSetNoInactiveRootWarn(ark->arkode);
    int flag = ARKStepSetTableNum(ark->arkode, ark->variant.dirk, ark->variant.erk);
    if (flag != ARK_SUCCESS)
        return fail(ark, err, "ARKStepSetTableNum", flag);
    if (ark->variant.kind != KIND_EXPLICIT) {
        if (use_band(ark, n)) {
            sunindextype bw = (sunindextype)ark->problem.half_bandwidth;
            ark->matrix = SUNBandMatrix(len, bw, bw, ark->ctx);
            ark->linear_solver = ark->matrix ? SUNLinSol_Band(ark->y, ark->matrix, ark->ctx) : NULL;
        } else {
            ark->matrix = SUNDenseMatrix(len, len, ark->ctx);
            ark->linear_solver = ark->matrix ? SUNLinSol_Dense(ark->y, ark->matrix, ark->ctx) : NULL;
        }
        if (!ark->linear_solver)
            return BK_FAIL(err, BK_ERR_NOMEM, "ARKODE: cannot create the linear solver (n = %zu)", n);
        flag = ARKStepSetLinearSolver(ark->arkode, ark->linear_solver, ark->matrix);
        if (flag != ARK_SUCCESS)
            return fail(ark, err, "ARKStepSetLinearSolver", flag);
        if (ark->problem.jacobian && (flag = ARKStepSetJacFn(ark->arkode, jacobian_adapter)) != ARK_SUCCESS)
            return fail(ark, err, "ARKStepSetJacFn", flag);
        /* Rebuild the Newton matrix whenever gamma = h a_ii changes.  With ARKODE 6.4.1's
         * default (reuse while |gamma/gamma_old - 1| < 0.2) a step shortened by up to 20%
         * -- e.g. the last one, clipped to the stop time -- is solved with the stale
         * matrix, the convergence test trusts the rate remembered from earlier steps, one
         * Newton iteration passes, and the embedded error estimate, built from the same
         * wrong stages, accepts the step: errors of 1e-6 at rtol 1e-10 on a harmonic
         * oscillator (every DIRK table tried).  h only changes outside ARKODE's fixed-step
         * band [1, 1.5], so this costs a Jacobian per change of h, not per step. */
        if ((flag = ARKStepSetDeltaGammaMax(ark->arkode, 1e-9)) != ARK_SUCCESS)
            return fail(ark, err, "ARKStepSetDeltaGammaMax", flag);
    }
    ark->n = n;
    return BK_OK;
}

static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    arkode_backend *ark = mem;
    ark->problem = *problem;
    ark->message[0] = '\0';
    add_counters(ark, &ark->done);
    int flag;
    if (ark->arkode && ark->n == n) {
        memcpy(N_VGetArrayPointer(ark->y), y0, n * sizeof *y0);
        /* Keeps the tables, the linear solver and every option set before. */
        flag = ARKStepReInit(ark->arkode, explicit_fn(ark), implicit_fn(ark), t0, ark->y);
        if (flag != ARK_SUCCESS)
            return fail(ark, err, "ARKStepReInit", flag);
    } else {
        free_objects(ark);
        int rc = build_objects(ark, n, t0, y0, err);
        if (rc != BK_OK) {
            free_objects(ark);
            return rc;
        }
    }
    memcpy(N_VGetArrayPointer(ark->atol), atol, n * sizeof *atol);
    if ((flag = ARKStepSVtolerances(ark->arkode, ark->options.rtol, ark->atol)) != ARK_SUCCESS)
        return fail(ark, err, "ARKStepSVtolerances", flag);
    if ((int)problem->n_roots != ark->n_roots) {
        flag = ARKStepRootInit(ark->arkode, (int)problem->n_roots,
                               problem->n_roots ? roots_adapter : NULL);
        if (flag != ARK_SUCCESS)
            return fail(ark, err, "ARKStepRootInit", flag);
        ark->n_roots = (int)problem->n_roots;
    }
    if (problem->n_roots > 0) {
        /* ARKODE copies the directions; the cast only drops const from its prototype. */
        flag = ARKStepSetRootDirection(ark->arkode, (int *)(uintptr_t)problem->root_direction);
        if (flag != ARK_SUCCESS)
            return fail(ark, err, "ARKStepSetRootDirection", flag);
    }
    if ((flag = ARKStepSetStopTime(ark->arkode, t_stop)) != ARK_SUCCESS)
        return fail(ark, err, "ARKStepSetStopTime", flag);
    if (isfinite(ark->options.max_step) && ark->options.max_step > 0 &&
        (flag = ARKStepSetMaxStep(ark->arkode, ark->options.max_step)) != ARK_SUCCESS)
        return fail(ark, err, "ARKStepSetMaxStep", flag);
    ark->t_stop = t_stop;
    return BK_OK;
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    arkode_backend *ark = mem;
    sunrealtype t = 0.0;
    int flag = ARKStepEvolve(ark->arkode, ark->t_stop, ark->y, &t, ARK_ONE_STEP);
    *t_reached = t;
    memcpy(y, N_VGetArrayPointer(ark->y), ark->n * sizeof *y);
    switch (flag) {
    case ARK_SUCCESS:
        return BK_STEP_OK;
    case ARK_ROOT_RETURN:
        return BK_STEP_ROOT;
    case ARK_TSTOP_RETURN:
        return BK_STEP_STOP;
    default:
        return fail(ark, err, "ARKStepEvolve", flag);
    }
}

static int interpolate(void *mem, double t, double *y, bk_error *err)
{
    arkode_backend *ark = mem;
    int flag = ARKStepGetDky(ark->arkode, t, 0, ark->work);
    if (flag != ARK_SUCCESS)
        return fail(ark, err, "ARKStepGetDky", flag);
    memcpy(y, N_VGetArrayPointer(ark->work), ark->n * sizeof *y);
    return BK_OK;
}

static void last_step(void *mem, double *t_lo, double *t_hi)
{
    arkode_backend *ark = mem;
    sunrealtype tn = 0.0, h = 0.0;
    ARKStepGetCurrentTime(ark->arkode, &tn);
    ARKStepGetLastStep(ark->arkode, &h);
    *t_hi = tn;
    *t_lo = tn - h;
}

static int root_info(void *mem, int *found)
{
    arkode_backend *ark = mem;
    return ARKStepGetRootInfo(ark->arkode, found) == ARK_SUCCESS ? BK_OK : BK_ERR_SOLVER;
}

static void counters(void *mem, bk_solver_counters *c)
{
    arkode_backend *ark = mem;
    *c = ark->done;
    add_counters(ark, c);
}

static void destroy(void *mem)
{
    arkode_backend *ark = mem;
    if (!ark)
        return;
    free_objects(ark);
    SUNContext_Free(&ark->ctx);
    free(ark);
}

#define ARKODE_BACKEND(NAME, CREATE, DOC)                                                       \
    {                                                                                           \
        .name = NAME, .doc = DOC, .create = CREATE, .start = start, .step = step,               \
        .interpolate = interpolate, .last_step = last_step, .root_info = root_info,             \
        .counters = counters, .destroy = destroy,                                               \
    }

const bk_solver_backend bk_solver_arkode_bs23 = ARKODE_BACKEND(
    "arkode_bs23", create_bs23,
    "ARKODE explicit Bogacki-Shampine 3(2), 4 stages (MATLAB ode23's pair): non-stiff");
const bk_solver_backend bk_solver_arkode_dp45 = ARKODE_BACKEND(
    "arkode_dp45", create_dp45,
    "ARKODE explicit Dormand-Prince 5(4), 7 stages (MATLAB ode45's pair): non-stiff");
const bk_solver_backend bk_solver_arkode_erk = ARKODE_BACKEND(
    "arkode_erk", create_erk,
    "ARKODE explicit Zonneveld 4(3), 5 stages (ARKStep's default order-4 ERK): non-stiff");
const bk_solver_backend bk_solver_arkode_dirk = ARKODE_BACKEND(
    "arkode_dirk", create_dirk,
    "ARKODE SDIRK 4(3), 5 stages, L-stable (ARKStep's default order-4 DIRK), Newton with "
    "dense/band direct solver: stiff");
const bk_solver_backend bk_solver_arkode_imex = ARKODE_BACKEND(
    "arkode_imex", create_imex,
    "ARKODE additive ARK4(3)6L[2]SA with the whole right-hand side implicit (explicit part "
    "zero; no split is exposed), Newton with dense/band direct solver: stiff");
