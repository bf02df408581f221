/* IDA back-end: variable-order BDF (orders 1-5) on the residual
 *   F(t, y, y') = diag(id) y' - f(t, y) = 0,
 * Newton iteration with a dense or band direct linear solver on the exact iteration matrix
 * dF/dy + c_j dF/dy' = c_j diag(id) - df/dy.
 *
 * IDA is the one back-end that can pose a stuck block as what it is, a constraint, so it
 * asks for the scene's full layout (wants_full_layout): every block keeps (xi, v) in the
 * unknowns, a stuck block's rows being xi' = v (differential) and v = 0 (algebraic,
 * IDASetId 0).  The price is 2 unknowns per stuck block; the band stays the neighbours'.
 * The constraint pins v to 0 inside IDA's own Newton iteration, so a stuck block's slip
 * stays 0 without the run loop removing it, and the vector keeps its size across
 * transitions: a restart is an IDAReInit with new ids, never a rebuild.
 *
 * Every start is consistent as given: differential rows get y' = f(t0, y0); the only
 * algebraic rows are stuck blocks' v = 0, which the start vector satisfies with y' = 0.
 * So no IDACalcIC.  An ODE problem (differential_id NULL, as the solver battery poses) is
 * the special case id = 1.
 *
 * Root finding and dense output are IDA's own; as with CVODE the state returned at a root
 * is just past the crossing.  rhs_evals counts residual evaluations (one f each), those for
 * a difference-quotient Jacobian, and the f(t0, y0) of every start. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ida/ida.h>
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

typedef struct ida_backend {
    bk_solver_options options;
    SUNContext ctx;
    void *ida;
    N_Vector y, yp, atol, id, work;
    SUNMatrix matrix;
    SUNLinearSolver linear_solver;
    size_t n;                     /* size the IDA objects were built for */
    int n_roots;                  /* size RootInit was called with */
    bk_ode_problem problem;
    double t_stop;
    double *yp0;                  /* f(t0, y0) at the last start, capacity entries */
    size_t capacity;
    bk_solver_counters done;      /* counters of finished starts */
    char message[512];            /* last message from IDA's error handler */
} ida_backend;

static void capture_message(int error_code, const char *module, const char *function,
                            char *msg, void *user)
{
    ida_backend *ida = user;
    snprintf(ida->message, sizeof ida->message, "%s (%s, code %d)", msg,
             function ? function : module, error_code);
}

/* F = diag(id) y' - f(t, y); f's return convention (> 0 recoverable, < 0 fatal) is IDA's. */
static int residual(sunrealtype t, N_Vector y, N_Vector yp, N_Vector r, void *user)
{
    ida_backend *ida = user;
    double *rr = N_VGetArrayPointer(r);
    int rc = ida->problem.rhs(t, N_VGetArrayPointer(y), rr, ida->problem.user);
    if (rc != 0)
        return rc;
    const double *ypp = N_VGetArrayPointer(yp), *id = ida->problem.differential_id;
    size_t n = (size_t)N_VGetLength(r);
    for (size_t k = 0; k < n; ++k)
        rr[k] = (id && id[k] == 0.0 ? 0.0 : ypp[k]) - rr[k];
    return 0;
}

static int roots_adapter(sunrealtype t, N_Vector y, N_Vector yp, sunrealtype *g, void *user)
{
    (void)yp;
    ida_backend *ida = user;
    return ida->problem.roots(t, N_VGetArrayPointer(y), g, ida->problem.user);
}

static void add_counters(ida_backend *ida, bk_solver_counters *c)
{
    long steps = 0, res = 0, res_ls = 0, roots = 0, fails = 0, iters = 0;
    if (ida->ida) {
        IDAGetNumSteps(ida->ida, &steps);
        IDAGetNumResEvals(ida->ida, &res);
        IDAGetNumLinResEvals(ida->ida, &res_ls);
        IDAGetNumGEvals(ida->ida, &roots);
        IDAGetNumErrTestFails(ida->ida, &fails);
        IDAGetNumNonlinSolvIters(ida->ida, &iters);
    }
    c->steps += steps;
    c->rhs_evals += res + res_ls;
    c->root_evals += roots;
    c->err_test_fails += fails;
    c->nonlin_iters += iters;
}

static void free_objects(ida_backend *ida)
{
    if (ida->ida)
        IDAFree(&ida->ida);
    if (ida->linear_solver)
        SUNLinSolFree(ida->linear_solver);
    if (ida->matrix)
        SUNMatDestroy(ida->matrix);
    N_Vector *owned[] = {&ida->y, &ida->yp, &ida->atol, &ida->id, &ida->work};
    const size_t n_owned = sizeof(owned) / sizeof(owned[0]);
    for (size_t k = 0; k < n_owned; ++k) {
        N_Vector *slot = owned[k];
        if (*slot)
            N_VDestroy(*slot);
        *slot = NULL;
    }
    ida->ida = NULL;
    ida->linear_solver = NULL;
    ida->matrix = NULL;
    ida->n = 0;
    ida->n_roots = -1;
}

static int fail(ida_backend *ida, bk_error *err, const char *what, int flag)
{
    char *flag_name = IDAGetReturnFlagName(flag); /* malloc'ed by SUNDIALS */
    BK_FAIL(err, BK_ERR_SOLVER, "IDA: %s failed (flag %d: %s)%s%s", what, flag,
            flag_name ? flag_name : "?", ida->message[0] ? ": " : "", ida->message);
    free(flag_name);
    return BK_ERR_SOLVER;
}

/* d(residual)/dy + cj d(residual)/dy' for the residual diag(id) y' - f(t, y): cj diag(id) - J. */
static int jacobian_adapter(sunrealtype t, sunrealtype cj, N_Vector y, N_Vector yp, N_Vector r,
                            SUNMatrix jac, void *user, N_Vector tmp1, N_Vector tmp2, N_Vector tmp3)
{
    (void)yp;
    (void)r;
    (void)tmp1;
    (void)tmp2;
    (void)tmp3;
    ida_backend *ida = user;
    return bk_sundials_jacobian(&ida->problem, t, N_VGetArrayPointer(y), jac, -1.0, cj);
}

static int create(void **mem, const bk_solver_options *options, bk_error *err)
{
    ida_backend *ida = calloc(1, sizeof *ida);
    if (!ida)
        return BK_FAIL(err, BK_ERR_NOMEM, "IDA back-end: out of memory");
    ida->options = *options;
    ida->n_roots = -1;
    if (SUNContext_Create(NULL, &ida->ctx) != 0) {
        free(ida);
        return BK_FAIL(err, BK_ERR_SOLVER, "IDA back-end: SUNContext_Create failed");
    }
    *mem = ida;
    return BK_OK;
}

static int use_band(const ida_backend *ida, size_t n)
{
    if (strcmp(ida->options.linear_solver, "band") == 0)
        return 1;
    if (strcmp(ida->options.linear_solver, "dense") == 0)
        return 0;
    return n > BAND_THRESHOLD && 2 * ida->problem.half_bandwidth + 1 < n;
}

static int build_objects(ida_backend *ida, size_t n, double t0, const double *y0,
                         const double *yp0, bk_error *err)
{
    sunindextype len = (sunindextype)n;
    ida->y = N_VNew_Serial(len, ida->ctx);
    ida->yp = N_VNew_Serial(len, ida->ctx);
    ida->atol = N_VNew_Serial(len, ida->ctx);
    ida->id = N_VNew_Serial(len, ida->ctx);
    ida->work = N_VNew_Serial(len, ida->ctx);
    ida->ida = IDACreate(ida->ctx);
    if (!ida->y || !ida->yp || !ida->atol || !ida->id || !ida->work || !ida->ida)
        return BK_FAIL(err, BK_ERR_NOMEM, "IDA: cannot allocate a problem of size %zu", n);
    memcpy(N_VGetArrayPointer(ida->y), y0, n * sizeof *y0);
    memcpy(N_VGetArrayPointer(ida->yp), yp0, n * sizeof *yp0);
    IDASetErrHandlerFn(ida->ida, capture_message, ida);
    int flag = IDAInit(ida->ida, residual, t0, ida->y, ida->yp);
    if (flag != IDA_SUCCESS)
        return fail(ida, err, "IDAInit", flag);
    IDASetUserData(ida->ida, ida);
    IDASetNoInactiveRootWarn(ida->ida);
    if (use_band(ida, n)) {
        sunindextype bw = (sunindextype)ida->problem.half_bandwidth;
        ida->matrix = SUNBandMatrix(len, bw, bw, ida->ctx);
        ida->linear_solver = ida->matrix ? SUNLinSol_Band(ida->y, ida->matrix, ida->ctx) : NULL;
    } else {
        ida->matrix = SUNDenseMatrix(len, len, ida->ctx);
        ida->linear_solver = ida->matrix ? SUNLinSol_Dense(ida->y, ida->matrix, ida->ctx) : NULL;
    }
    if (!ida->linear_solver)
        return BK_FAIL(err, BK_ERR_NOMEM, "IDA: cannot create the linear solver (n = %zu)", n);
    if ((flag = IDASetLinearSolver(ida->ida, ida->linear_solver, ida->matrix)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetLinearSolver", flag);
    if (ida->problem.jacobian && (flag = IDASetJacFn(ida->ida, jacobian_adapter)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetJacFn", flag);
    ida->n = n;
    return BK_OK;
}

static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    ida_backend *ida = mem;
    ida->problem = *problem;
    ida->message[0] = '\0';
    add_counters(ida, &ida->done);
    if (n > ida->capacity) {
        double *grown = realloc(ida->yp0, n * sizeof *grown);
        if (!grown)
            return BK_FAIL(err, BK_ERR_NOMEM, "IDA: cannot allocate a problem of size %zu", n);
        ida->yp0 = grown;
        ida->capacity = n;
    }
    /* The consistent initial derivative: f, and 0 for the algebraic rows. */
    ida->done.rhs_evals++;
    int rc = problem->rhs(t0, y0, ida->yp0, problem->user);
    if (rc != 0)
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "IDA: the right-hand side failed at the start, t = %.17g s (%d)", t0, rc);
    for (size_t k = 0; k < n && problem->differential_id; ++k)
        if (problem->differential_id[k] == 0.0)
            ida->yp0[k] = 0.0;
    int flag;
    if (ida->ida && ida->n == n) {
        memcpy(N_VGetArrayPointer(ida->y), y0, n * sizeof *y0);
        memcpy(N_VGetArrayPointer(ida->yp), ida->yp0, n * sizeof *y0);
        if ((flag = IDAReInit(ida->ida, t0, ida->y, ida->yp)) != IDA_SUCCESS)
            return fail(ida, err, "IDAReInit", flag);
    } else {
        free_objects(ida);
        rc = build_objects(ida, n, t0, y0, ida->yp0, err);
        if (rc != BK_OK) {
            free_objects(ida);
            return rc;
        }
    }
    if (problem->differential_id)
        memcpy(N_VGetArrayPointer(ida->id), problem->differential_id, n * sizeof *ida->yp0);
    else
        N_VConst(1.0, ida->id);
    if ((flag = IDASetId(ida->ida, ida->id)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetId", flag);
    memcpy(N_VGetArrayPointer(ida->atol), atol, n * sizeof *atol);
    if ((flag = IDASVtolerances(ida->ida, ida->options.rtol, ida->atol)) != IDA_SUCCESS)
        return fail(ida, err, "IDASVtolerances", flag);
    if ((int)problem->n_roots != ida->n_roots) {
        flag = IDARootInit(ida->ida, (int)problem->n_roots, problem->n_roots ? roots_adapter : NULL);
        if (flag != IDA_SUCCESS)
            return fail(ida, err, "IDARootInit", flag);
        ida->n_roots = (int)problem->n_roots;
    }
    if (problem->n_roots > 0) {
        /* IDA copies the directions; the cast only drops const from its prototype. */
        flag = IDASetRootDirection(ida->ida, (int *)(uintptr_t)problem->root_direction);
        if (flag != IDA_SUCCESS)
            return fail(ida, err, "IDASetRootDirection", flag);
    }
    if ((flag = IDASetStopTime(ida->ida, t_stop)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetStopTime", flag);
    if (isfinite(ida->options.max_step) && ida->options.max_step > 0 &&
        (flag = IDASetMaxStep(ida->ida, ida->options.max_step)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetMaxStep", flag);
    ida->t_stop = t_stop;
    return BK_OK;
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    ida_backend *ida = mem;
    sunrealtype t = 0.0;
    int flag = IDASolve(ida->ida, ida->t_stop, &t, ida->y, ida->yp, IDA_ONE_STEP);
    *t_reached = t;
    memcpy(y, N_VGetArrayPointer(ida->y), ida->n * sizeof *y);
    switch (flag) {
    case IDA_SUCCESS:
        return BK_STEP_OK;
    case IDA_ROOT_RETURN:
        return BK_STEP_ROOT;
    case IDA_TSTOP_RETURN:
        return BK_STEP_STOP;
    default:
        return fail(ida, err, "IDASolve step", flag);
    }
}

static int interpolate(void *mem, double t, double *y, bk_error *err)
{
    ida_backend *ida = mem;
    int flag = IDAGetDky(ida->ida, t, 0, ida->work);
    if (flag != IDA_SUCCESS)
        return fail(ida, err, "IDAGetDky", flag);
    memcpy(y, N_VGetArrayPointer(ida->work), ida->n * sizeof *y);
    return BK_OK;
}

static void last_step(void *mem, double *t_lo, double *t_hi)
{
    ida_backend *ida = mem;
    sunrealtype tn = 0.0, h = 0.0;
    IDAGetCurrentTime(ida->ida, &tn);
    IDAGetLastStep(ida->ida, &h);
    *t_hi = tn;
    *t_lo = tn - h;
}

static int root_info(void *mem, int *found)
{
    ida_backend *ida = mem;
    return IDAGetRootInfo(ida->ida, found) == IDA_SUCCESS ? BK_OK : BK_ERR_SOLVER;
}

static void counters(void *mem, bk_solver_counters *c)
{
    ida_backend *ida = mem;
    *c = ida->done;
    add_counters(ida, c);
}

static void destroy(void *mem)
{
    ida_backend *ida = mem;
    if (!ida)
        return;
    free_objects(ida);
    SUNContext_Free(&ida->ctx);
    free(ida->yp0);
    free(ida);
}

const bk_solver_backend bk_solver_ida = {
    .name = "ida",
    .doc = "IDA variable-order BDF (orders 1-5) on the DAE with stuck blocks as algebraic "
           "rows v = 0 (2 extra unknowns per stuck block), Newton with dense/band direct "
           "solver: stiff",
    .wants_full_layout = 1,
    .create = create,
    .start = start,
    .step = step,
    .interpolate = interpolate,
    .last_step = last_step,
    .root_info = root_info,
    .counters = counters,
    .destroy = destroy,
};
