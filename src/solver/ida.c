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
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <ida/ida.h>
#include <nvector/nvector_serial.h>

#include "bksim/solver.h"
#include "sundials_common.h"
#include "sundials_jacobian.h"

typedef struct ida_backend {
    bk_sundials_base base;        /* first: the state is its base (sundials_common.h) */
    void *ida;
    N_Vector yp, id;
    double *yp0;                  /* f(t0, y0) at the last start, capacity entries */
    size_t capacity;
} ida_backend;
_Static_assert(offsetof(ida_backend, base) == 0, "the state is allocated and freed through its base");

/* F = diag(id) y' - f(t, y); f's return convention (> 0 recoverable, < 0 fatal) is IDA's. */
static int residual(sunrealtype t, N_Vector y, N_Vector yp, N_Vector r, void *user)
{
    ida_backend *ida = user;
    double *rr = N_VGetArrayPointer(r);
    int rc = ida->base.problem.rhs(t, N_VGetArrayPointer(y), rr, ida->base.problem.user);
    if (rc != 0)
        return rc;
    const double *ypp = N_VGetArrayPointer(yp), *id = ida->base.problem.differential_id;
    size_t n = (size_t)N_VGetLength(r);
    for (size_t k = 0; k < n; ++k)
        rr[k] = (id && id[k] == 0.0 ? 0.0 : ypp[k]) - rr[k];
    return 0;
}

static int roots_adapter(sunrealtype t, N_Vector y, N_Vector yp, sunrealtype *g, void *user)
{
    (void)yp;
    ida_backend *ida = user;
    return ida->base.problem.roots(t, N_VGetArrayPointer(y), g, ida->base.problem.user);
}

/* The counters of the current start, as IDA reports them. */
static bk_solver_counters this_start(const ida_backend *ida)
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
    return (bk_solver_counters){.steps = steps, .rhs_evals = res + res_ls, .root_evals = roots,
                                .err_test_fails = fails, .nonlin_iters = iters};
}

static void free_objects(ida_backend *ida)
{
    if (ida->ida)
        IDAFree(&ida->ida);
    if (ida->yp)
        N_VDestroy(ida->yp);
    if (ida->id)
        N_VDestroy(ida->id);
    ida->ida = NULL;
    ida->yp = ida->id = NULL;
    bk_sundials_free_objects(&ida->base);
}

static int fail(const ida_backend *ida, bk_error *err, const char *what, int flag)
{
    return bk_sundials_fail(&ida->base, err, what, flag);
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
    return bk_sundials_jacobian(&ida->base.problem, t, N_VGetArrayPointer(y), jac, -1.0, cj);
}

static int create(void **mem, const bk_solver_options *options, bk_error *err)
{
    return bk_sundials_create(mem, sizeof(ida_backend), "IDA", IDAGetReturnFlagName, options, err);
}

static int build_objects(ida_backend *ida, size_t n, double t0, const double *y0,
                         const double *yp0, bk_error *err)
{
    bk_sundials_base *base = &ida->base;
    int rc = bk_sundials_new_vectors(base, n, err);
    if (rc != BK_OK)
        return rc;
    ida->yp = N_VNew_Serial((sunindextype)n, base->ctx);
    ida->id = N_VNew_Serial((sunindextype)n, base->ctx);
    ida->ida = IDACreate(base->ctx);
    if (!ida->yp || !ida->id || !ida->ida)
        return bk_sundials_no_memory(base, n, err);
    memcpy(N_VGetArrayPointer(base->y), y0, n * sizeof *y0);
    memcpy(N_VGetArrayPointer(ida->yp), yp0, n * sizeof *yp0);
    IDASetErrHandlerFn(ida->ida, bk_sundials_capture_message, base);
    int flag = IDAInit(ida->ida, residual, t0, base->y, ida->yp);
    if (flag != IDA_SUCCESS)
        return fail(ida, err, "IDAInit", flag);
    IDASetUserData(ida->ida, ida);
    IDASetNoInactiveRootWarn(ida->ida);
    if ((rc = bk_sundials_new_linear_solver(base, n, err)) != BK_OK)
        return rc;
    if ((flag = IDASetLinearSolver(ida->ida, base->linear_solver, base->matrix)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetLinearSolver", flag);
    if (base->problem.jacobian && (flag = IDASetJacFn(ida->ida, jacobian_adapter)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetJacFn", flag);
    base->n = n;
    return BK_OK;
}

static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    ida_backend *ida = mem;
    bk_sundials_base *base = &ida->base;
    bk_sundials_begin_start(base, problem, this_start(ida));
    if (n > ida->capacity) {
        double *grown = realloc(ida->yp0, n * sizeof *grown);
        if (!grown)
            return bk_sundials_no_memory(base, n, err);
        ida->yp0 = grown;
        ida->capacity = n;
    }
    /* The consistent initial derivative: f, and 0 for the algebraic rows. */
    base->done.rhs_evals++;
    int rc = problem->rhs(t0, y0, ida->yp0, problem->user);
    if (rc != 0)
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "IDA: the right-hand side failed at the start, t = %.17g s (%d)", t0, rc);
    for (size_t k = 0; k < n && problem->differential_id; ++k)
        if (problem->differential_id[k] == 0.0)
            ida->yp0[k] = 0.0;
    int flag;
    if (ida->ida && base->n == n) {
        memcpy(N_VGetArrayPointer(base->y), y0, n * sizeof *y0);
        memcpy(N_VGetArrayPointer(ida->yp), ida->yp0, n * sizeof *y0);
        if ((flag = IDAReInit(ida->ida, t0, base->y, ida->yp)) != IDA_SUCCESS)
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
    memcpy(N_VGetArrayPointer(base->atol), atol, n * sizeof *atol);
    if ((flag = IDASVtolerances(ida->ida, base->options.rtol, base->atol)) != IDA_SUCCESS)
        return fail(ida, err, "IDASVtolerances", flag);
    if ((int)problem->n_roots != base->n_roots) {
        flag = IDARootInit(ida->ida, (int)problem->n_roots, problem->n_roots ? roots_adapter : NULL);
        if (flag != IDA_SUCCESS)
            return fail(ida, err, "IDARootInit", flag);
        base->n_roots = (int)problem->n_roots;
    }
    if (problem->n_roots > 0) {
        /* IDA copies the directions; the cast only drops const from its prototype. */
        flag = IDASetRootDirection(ida->ida, (int *)(uintptr_t)problem->root_direction);
        if (flag != IDA_SUCCESS)
            return fail(ida, err, "IDASetRootDirection", flag);
    }
    if ((flag = IDASetStopTime(ida->ida, t_stop)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetStopTime", flag);
    if (isfinite(base->options.max_step) && base->options.max_step > 0 &&
        (flag = IDASetMaxStep(ida->ida, base->options.max_step)) != IDA_SUCCESS)
        return fail(ida, err, "IDASetMaxStep", flag);
    base->t_stop = t_stop;
    return BK_OK;
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    ida_backend *ida = mem;
    sunrealtype t = 0.0;
    int flag = IDASolve(ida->ida, ida->base.t_stop, &t, ida->base.y, ida->yp, IDA_ONE_STEP);
    *t_reached = t;
    memcpy(y, N_VGetArrayPointer(ida->base.y), ida->base.n * sizeof *y);
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
    int flag = IDAGetDky(ida->ida, t, 0, ida->base.work);
    if (flag != IDA_SUCCESS)
        return fail(ida, err, "IDAGetDky", flag);
    memcpy(y, N_VGetArrayPointer(ida->base.work), ida->base.n * sizeof *y);
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
    bk_sundials_counters(&ida->base, this_start(ida), c);
}

static void destroy(void *mem)
{
    ida_backend *ida = mem;
    if (!ida)
        return;
    free_objects(ida);
    free(ida->yp0);
    bk_sundials_destroy(&ida->base);
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
