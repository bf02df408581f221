/* ARKODE ARKStep back-ends: explicit Runge-Kutta pairs with a chosen Butcher table
 * (Bogacki-Shampine 3(2) as in MATLAB's ode23, Dormand-Prince 5(4) as in ode45, ARKODE's
 * default order-4 pair), a diagonally implicit method and an additive (IMEX) pair, the last
 * two with Newton iteration and a dense or band direct linear solver.
 *
 * The implicit methods meet stiffness far beyond what a step resolves: a rate-and-state
 * block's slip rate relaxes onto its force balance at -(d F/d v + damping) / m, 1e12-1e17
 * 1/s between events for masses of 1e-5-1 kg (d F/d v = a N / v), so h |d f/d y| reaches
 * 1e8-1e15 and the slip rate is, to the tolerance, an algebraic variable.  Three settings
 * follow (issue 32):
 *  - arkode_dirk's own table is Kennedy & Carpenter's ESDIRK4(3I)6L[2]SA
 *    (ARKODE_ESDIRK43I6L2SA_6_3_4): stiffly accurate, stage order 2, method and embedding
 *    both L-stable.  ARKStep's default order-4 DIRK, SDIRK 5_3_4 (Hairer & Wanner's SDIRK4),
 *    has stage order 1 and an embedding whose stability function is 3.3 at infinity: its
 *    error estimate on a variable that sits on its slow manifold does not fall with h (the
 *    QDYN spring-block failed its error test at h = 5e-10 s within the first millisecond,
 *    at every mass; with the two settings below it still stalled at t = 170 s after 1.2e6
 *    steps, where cvode_bdf takes 4.4e4 for the 300 s at rtol 1e-8).  Of the 15 tables
 *    tried, ESDIRK4(3I)6L[2]SA took the fewest steps there (5.6e3 at rtol 1e-8,
 *    1.7e4 at 1e-10; ESDIRK4(3)6L[2]SA 2.9e4 and 1.4e5; the order-5 ESDIRKs and Kvaerno
 *    7_4_5 stalled in the first 0.01 s).  SDIRK 5_3_4 stays selectable ([solver]
 *    arkode_table).
 *  - Stage derivatives are deduced from the stage equation, f_i = (z_i - a_i) / (h a_ii)
 *    (ARKStepSetDeduceImplicitRhs), not evaluated as f(z_i): the evaluation multiplies
 *    the Newton iteration's residual by |d f/d y|, and that amplified residual fed both the
 *    step and its error estimate (SUNDIALS' own advice when h a_ii L > 1, ARKODE guide
 *    "Nonlinear solver methods").  The Hermite dense output reads the last (deduced) stage
 *    derivative as f at the step's end (the tables here end with c = 1).
 *  - Newton starts from the previous step's dense output extrapolated to the stage time
 *    (predictor 1, "maximum order") instead of y_n: the slip rate grows or decays by orders
 *    of magnitude within a step around events, and from y_n, whose friction Jacobian
 *    (a N / v) is then off by as much, three iterations did not converge: convergence
 *    failures, not accuracy, held the step (ESDIRK4(3I) on the QDYN block at rtol 1e-8:
 *    107507 steps from y_n, 5646 with the predictor).
 *
 * IMEX split (arkode_imex, Kennedy & Carpenter's ARK4(3)6L[2]SA): the problem's
 * rhs_split gives the friction terms (stiff: the direct effect at low slip rates, the
 * state's relaxation at small L0) to the ESDIRK half, with their own Jacobian
 * (jacobian_implicit), and the springs, kinematics and energy quadratures to the explicit
 * half.  ARKODE asks for both halves at each stage point; one rhs_split call, cached per
 * (t, y), serves both.  A problem without a split runs the whole right-hand side
 * implicitly, as arkode_dirk does but with the ARK pair's ESDIRK table.  The split needs an
 * underdamped block: where friction or dashpots overdamp it (rate-and-state, d F/d v =
 * a N / v), the spring term k x / m left in the explicit half is the stiff one, and the
 * step is held to ~30 sqrt(rtol m / k) (the QDYN block: 2.5e-9 s at 1e-3 kg, 7e-8 s at
 * 1 kg, rtol 1e-8), whatever the implicit half does (issue 32).
 *
 * Dense output and root finding are ARKODE's own (Hermite interpolation of the step,
 * roots located on it); the state returned at a root is at ARKODE's upper bracket, just
 * past the crossing, as with CVODE.  Like cvode.c, a restart of equal size reinitialises
 * and a size change rebuilds every object.
 *
 * rhs_evals counts right-hand-side evaluations (for arkode_imex: rhs_split calls, each
 * giving both halves) plus those ARKODE makes for difference-quotient Jacobians
 * (ARKStepGetNumLinRhsEvals). */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <nvector/nvector_serial.h>

#include "bksim/solver.h"
#include "sundials_common.h"
#include "sundials_jacobian.h"

typedef enum { KIND_EXPLICIT, KIND_IMPLICIT, KIND_IMEX } ark_kind;

typedef struct ark_variant {
    ark_kind kind;
    ARKODE_ERKTableID erk;
    ARKODE_DIRKTableID dirk;
    int takes_table; /* [solver] arkode_table replaces the table (arkode_erk, arkode_dirk) */
} ark_variant;

static const ark_variant variant_bs23 = {KIND_EXPLICIT, ARKODE_BOGACKI_SHAMPINE_4_2_3, ARKODE_DIRK_NONE, 0};
static const ark_variant variant_dp45 = {KIND_EXPLICIT, ARKODE_DORMAND_PRINCE_7_4_5, ARKODE_DIRK_NONE, 0};
static const ark_variant variant_erk = {KIND_EXPLICIT, ARKODE_ZONNEVELD_5_3_4, ARKODE_DIRK_NONE, 1};
static const ark_variant variant_dirk = {KIND_IMPLICIT, ARKODE_ERK_NONE, ARKODE_ESDIRK43I6L2SA_6_3_4, 1};
static const ark_variant variant_imex = {KIND_IMEX, ARKODE_ARK436L2SA_ERK_6_3_4, ARKODE_ARK436L2SA_DIRK_6_3_4, 0};

/* The tables [solver] arkode_table selects.  Knoth-Wolke 3_3 is left out: it has no
 * embedding, so no error estimate for adaptive steps. */
#define TABLE(id) {#id, (int)id}
typedef struct named_table {
    const char *name;
    int id;
} named_table;
static const named_table erk_tables[] = {
    TABLE(ARKODE_HEUN_EULER_2_1_2), TABLE(ARKODE_BOGACKI_SHAMPINE_4_2_3), TABLE(ARKODE_ARK324L2SA_ERK_4_2_3),
    TABLE(ARKODE_ZONNEVELD_5_3_4), TABLE(ARKODE_ARK436L2SA_ERK_6_3_4), TABLE(ARKODE_SAYFY_ABURUB_6_3_4),
    TABLE(ARKODE_CASH_KARP_6_4_5), TABLE(ARKODE_FEHLBERG_6_4_5), TABLE(ARKODE_DORMAND_PRINCE_7_4_5),
    TABLE(ARKODE_ARK548L2SA_ERK_8_4_5), TABLE(ARKODE_VERNER_8_5_6), TABLE(ARKODE_FEHLBERG_13_7_8),
    TABLE(ARKODE_ARK437L2SA_ERK_7_3_4), TABLE(ARKODE_ARK548L2SAb_ERK_8_4_5),
};
static const named_table dirk_tables[] = {
    TABLE(ARKODE_SDIRK_2_1_2), TABLE(ARKODE_BILLINGTON_3_3_2), TABLE(ARKODE_TRBDF2_3_3_2),
    TABLE(ARKODE_KVAERNO_4_2_3), TABLE(ARKODE_ARK324L2SA_DIRK_4_2_3), TABLE(ARKODE_CASH_5_2_4),
    TABLE(ARKODE_CASH_5_3_4), TABLE(ARKODE_SDIRK_5_3_4), TABLE(ARKODE_KVAERNO_5_3_4),
    TABLE(ARKODE_ARK436L2SA_DIRK_6_3_4), TABLE(ARKODE_KVAERNO_7_4_5), TABLE(ARKODE_ARK548L2SA_DIRK_8_4_5),
    TABLE(ARKODE_ARK437L2SA_DIRK_7_3_4), TABLE(ARKODE_ARK548L2SAb_DIRK_8_4_5),
    TABLE(ARKODE_ESDIRK324L2SA_4_2_3), TABLE(ARKODE_ESDIRK325L2SA_5_2_3), TABLE(ARKODE_ESDIRK32I5L2SA_5_2_3),
    TABLE(ARKODE_ESDIRK436L2SA_6_3_4), TABLE(ARKODE_ESDIRK43I6L2SA_6_3_4), TABLE(ARKODE_QESDIRK436L2SA_6_3_4),
    TABLE(ARKODE_ESDIRK437L2SA_7_3_4), TABLE(ARKODE_ESDIRK547L2SA_7_4_5), TABLE(ARKODE_ESDIRK547L2SA2_7_4_5),
};
#undef TABLE
#define N_ERK_TABLES (sizeof erk_tables / sizeof erk_tables[0])
#define N_DIRK_TABLES (sizeof dirk_tables / sizeof dirk_tables[0])

const char *bk_solver_arkode_table(size_t i)
{
    if (i == 0)
        return "default";
    if (i - 1 < N_ERK_TABLES)
        return erk_tables[i - 1].name;
    if (i - 1 - N_ERK_TABLES < N_DIRK_TABLES)
        return dirk_tables[i - 1 - N_ERK_TABLES].name;
    return NULL;
}

/* The id of `name` in the kind's list, or -1 ("default" is handled by the caller). */
static int table_id(ark_kind kind, const char *name)
{
    const named_table *list = kind == KIND_EXPLICIT ? erk_tables : dirk_tables;
    size_t n = kind == KIND_EXPLICIT ? N_ERK_TABLES : N_DIRK_TABLES;
    for (size_t k = 0; k < n; ++k)
        if (strcmp(list[k].name, name) == 0)
            return list[k].id;
    return -1;
}

static int check_table(ark_kind kind, const char *method, const bk_solver_options *options, char *message,
                       size_t len)
{
    if (!options->arkode_table[0] || strcmp(options->arkode_table, "default") == 0 ||
        table_id(kind, options->arkode_table) >= 0)
        return 0;
    const named_table *list = kind == KIND_EXPLICIT ? erk_tables : dirk_tables;
    size_t n = kind == KIND_EXPLICIT ? N_ERK_TABLES : N_DIRK_TABLES;
    int used = snprintf(message, len, "%s is not %s table (allowed for %s: default", options->arkode_table,
                        kind == KIND_EXPLICIT ? "an explicit (ERK)" : "a diagonally implicit (DIRK)", method);
    for (size_t k = 0; k < n && used > 0 && (size_t)used < len; ++k)
        used += snprintf(message + used, len - (size_t)used, ", %s", list[k].name);
    if (used > 0 && (size_t)used < len)
        snprintf(message + used, len - (size_t)used, ")");
    return -1;
}

static int check_erk(const bk_solver_options *options, char *message, size_t len)
{
    return check_table(KIND_EXPLICIT, "arkode_erk", options, message, len);
}

static int check_dirk(const bk_solver_options *options, char *message, size_t len)
{
    return check_table(KIND_IMPLICIT, "arkode_dirk", options, message, len);
}

typedef struct arkode_backend {
    bk_sundials_base base;        /* first: the state is its base (sundials_common.h) */
    ark_variant variant;
    void *arkode;
    int split;                    /* arkode_imex on a problem with rhs_split */
    double *cache_y, *cache_fe, *cache_fi; /* split: the last rhs_split, at (cache_t, cache_y) */
    double cache_t;
    int cache_valid;
    long split_evals;             /* rhs_split calls in the current start */
} arkode_backend;
_Static_assert(offsetof(arkode_backend, base) == 0, "the state is allocated and freed through its base");

static int rhs_adapter(sunrealtype t, N_Vector y, N_Vector ydot, void *user)
{
    arkode_backend *ark = user;
    return ark->base.problem.rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot), ark->base.problem.user);
}

/* One half of the IMEX split, from the cached rhs_split at (t, y). */
static int split_half(sunrealtype t, N_Vector y, N_Vector ydot, arkode_backend *ark, int implicit)
{
    const double *yy = N_VGetArrayPointer(y);
    size_t n = ark->base.n;
    if (!(ark->cache_valid && ark->cache_t == t && memcmp(ark->cache_y, yy, n * sizeof *yy) == 0)) {
        ark->cache_valid = 0;
        ark->split_evals++;
        int rc = ark->base.problem.rhs_split(t, yy, ark->cache_fe, ark->cache_fi, ark->base.problem.user);
        if (rc != 0)
            return rc;
        memcpy(ark->cache_y, yy, n * sizeof *yy);
        ark->cache_t = t;
        ark->cache_valid = 1;
    }
    memcpy(N_VGetArrayPointer(ydot), implicit ? ark->cache_fi : ark->cache_fe, n * sizeof *yy);
    return 0;
}

static int explicit_half(sunrealtype t, N_Vector y, N_Vector ydot, void *user)
{
    return split_half(t, y, ydot, user, 0);
}

static int implicit_half(sunrealtype t, N_Vector y, N_Vector ydot, void *user)
{
    return split_half(t, y, ydot, user, 1);
}

static int roots_adapter(sunrealtype t, N_Vector y, sunrealtype *g, void *user)
{
    arkode_backend *ark = user;
    return ark->base.problem.roots(t, N_VGetArrayPointer(y), g, ark->base.problem.user);
}

static ARKRhsFn explicit_fn(const arkode_backend *ark)
{
    if (ark->split)
        return explicit_half;
    return ark->variant.kind == KIND_EXPLICIT ? rhs_adapter : NULL;
}

static ARKRhsFn implicit_fn(const arkode_backend *ark)
{
    if (ark->split)
        return implicit_half;
    return ark->variant.kind == KIND_EXPLICIT ? NULL : rhs_adapter;
}

/* The counters of the current start, as ARKODE reports them (rhs_split calls for a split). */
static bk_solver_counters this_start(const arkode_backend *ark)
{
    long steps = 0, fe = 0, fi = 0, fls = 0, roots = 0, fails = 0, iters = 0;
    if (ark->arkode) {
        ARKStepGetNumSteps(ark->arkode, &steps);
        ARKStepGetNumRhsEvals(ark->arkode, &fe, &fi);
        /* ARKODE 6.4's RootInit with no functions leaves this count uninitialised. */
        if (ark->base.n_roots > 0)
            ARKStepGetNumGEvals(ark->arkode, &roots);
        ARKStepGetNumErrTestFails(ark->arkode, &fails);
        if (implicit_fn(ark)) {
            ARKStepGetNumNonlinSolvIters(ark->arkode, &iters);
            ARKStepGetNumLinRhsEvals(ark->arkode, &fls);
        }
    }
    long rhs = (ark->split ? ark->split_evals : fe + fi) + fls;
    return (bk_solver_counters){.steps = steps, .rhs_evals = rhs, .root_evals = roots,
                                .err_test_fails = fails, .nonlin_iters = iters};
}

static void free_objects(arkode_backend *ark)
{
    if (ark->arkode)
        ARKStepFree(&ark->arkode);
    free(ark->cache_y);
    free(ark->cache_fe);
    free(ark->cache_fi);
    ark->cache_y = ark->cache_fe = ark->cache_fi = NULL;
    ark->cache_valid = 0;
    ark->arkode = NULL;
    bk_sundials_free_objects(&ark->base);
}

static int fail(const arkode_backend *ark, bk_error *err, const char *what, int flag)
{
    return bk_sundials_fail(&ark->base, err, what, flag);
}

/* The exact Jacobian of the implicit part: the whole right-hand side's, or (IMEX) the
 * friction's. */
static int jacobian_adapter(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix jac, void *user,
                            N_Vector tmp1, N_Vector tmp2, N_Vector tmp3)
{
    (void)fy;
    (void)tmp1;
    (void)tmp2;
    (void)tmp3;
    arkode_backend *ark = user;
    bk_ode_problem implicit_part = ark->base.problem;
    if (ark->split)
        implicit_part.jacobian = ark->base.problem.jacobian_implicit;
    return bk_sundials_jacobian(&implicit_part, t, N_VGetArrayPointer(y), jac, 1.0, 0.0);
}

static int create(void **mem, const bk_solver_options *options, const ark_variant *variant,
                  bk_error *err)
{
    int rc = bk_sundials_create(mem, sizeof(arkode_backend), "ARKODE", ARKStepGetReturnFlagName,
                                options, err);
    if (rc != BK_OK)
        return rc;
    arkode_backend *ark = *mem;
    ark->variant = *variant;
    /* A chosen table replaces the method's own (only arkode_erk and arkode_dirk take one). */
    int chosen = variant->takes_table && options->arkode_table[0] && strcmp(options->arkode_table, "default") != 0
                     ? table_id(variant->kind, options->arkode_table)
                     : -1;
    if (chosen >= 0 && variant->kind == KIND_EXPLICIT)
        ark->variant.erk = (ARKODE_ERKTableID)chosen;
    else if (chosen >= 0 && variant->kind == KIND_IMPLICIT)
        ark->variant.dirk = (ARKODE_DIRKTableID)chosen;
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

static int build_objects(arkode_backend *ark, size_t n, double t0, const double *y0, bk_error *err)
{
    bk_sundials_base *base = &ark->base;
    int rc = bk_sundials_new_vectors(base, n, err);
    if (rc != BK_OK)
        return rc;
    if (ark->split) {
        ark->cache_y = malloc(n * sizeof *ark->cache_y);
        ark->cache_fe = malloc(n * sizeof *ark->cache_fe);
        ark->cache_fi = malloc(n * sizeof *ark->cache_fi);
        if (!ark->cache_y || !ark->cache_fe || !ark->cache_fi)
            return bk_sundials_no_memory(base, n, err);
    }
    memcpy(N_VGetArrayPointer(base->y), y0, n * sizeof *y0);
    ark->arkode = ARKStepCreate(explicit_fn(ark), implicit_fn(ark), t0, base->y, base->ctx);
    if (!ark->arkode)
        return BK_FAIL(err, BK_ERR_NOMEM, "ARKODE: ARKStepCreate failed (size %zu)", n);
    ARKStepSetErrHandlerFn(ark->arkode, bk_sundials_capture_message, base);
    ARKStepSetUserData(ark->arkode, ark);
    ARKStepSetNoInactiveRootWarn(ark->arkode);
    /* Without a split, arkode_imex integrates everything with the pair's ESDIRK half. */
    ARKODE_ERKTableID erk = explicit_fn(ark) ? ark->variant.erk : ARKODE_ERK_NONE;
    int flag = ARKStepSetTableNum(ark->arkode, ark->variant.dirk, erk);
    if (flag != ARK_SUCCESS)
        return fail(ark, err, "ARKStepSetTableNum", flag);
    if (implicit_fn(ark)) {
        if ((rc = bk_sundials_new_linear_solver(base, n, err)) != BK_OK)
            return rc;
        flag = ARKStepSetLinearSolver(ark->arkode, base->linear_solver, base->matrix);
        if (flag != ARK_SUCCESS)
            return fail(ark, err, "ARKStepSetLinearSolver", flag);
        if ((ark->split ? base->problem.jacobian_implicit : base->problem.jacobian) &&
        (flag = ARKStepSetJacFn(ark->arkode, jacobian_adapter)) != ARK_SUCCESS)
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
        /* Stage derivatives from the stage equations and Newton from the extrapolated
         * dense output: see the top of the file. */
        if ((flag = ARKStepSetDeduceImplicitRhs(ark->arkode, SUNTRUE)) != ARK_SUCCESS)
            return fail(ark, err, "ARKStepSetDeduceImplicitRhs", flag);
        if ((flag = ARKStepSetPredictorMethod(ark->arkode, 1)) != ARK_SUCCESS)
            return fail(ark, err, "ARKStepSetPredictorMethod", flag);
    }
    base->n = n;
    return BK_OK;
}

static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    arkode_backend *ark = mem;
    bk_sundials_base *base = &ark->base;
    bk_sundials_begin_start(base, problem, this_start(ark));
    ark->split_evals = 0;
    ark->cache_valid = 0; /* the scene behind the right-hand side changed */
    int split = ark->variant.kind == KIND_IMEX && problem->rhs_split;
    int flag;
    if (ark->arkode && base->n == n && ark->split == split) {
        memcpy(N_VGetArrayPointer(base->y), y0, n * sizeof *y0);
        /* Keeps the tables, the linear solver and every option set before. */
        flag = ARKStepReInit(ark->arkode, explicit_fn(ark), implicit_fn(ark), t0, base->y);
        if (flag != ARK_SUCCESS)
            return fail(ark, err, "ARKStepReInit", flag);
    } else {
        free_objects(ark);
        ark->split = split;
        int rc = build_objects(ark, n, t0, y0, err);
        if (rc != BK_OK) {
            free_objects(ark);
            return rc;
        }
    }
    memcpy(N_VGetArrayPointer(base->atol), atol, n * sizeof *atol);
    if ((flag = ARKStepSVtolerances(ark->arkode, base->options.rtol, base->atol)) != ARK_SUCCESS)
        return fail(ark, err, "ARKStepSVtolerances", flag);
    if ((int)problem->n_roots != base->n_roots) {
        flag = ARKStepRootInit(ark->arkode, (int)problem->n_roots,
                               problem->n_roots ? roots_adapter : NULL);
        if (flag != ARK_SUCCESS)
            return fail(ark, err, "ARKStepRootInit", flag);
        base->n_roots = (int)problem->n_roots;
    }
    if (problem->n_roots > 0) {
        /* ARKODE copies the directions; the cast only drops const from its prototype. */
        flag = ARKStepSetRootDirection(ark->arkode, (int *)(uintptr_t)problem->root_direction);
        if (flag != ARK_SUCCESS)
            return fail(ark, err, "ARKStepSetRootDirection", flag);
    }
    if ((flag = ARKStepSetStopTime(ark->arkode, t_stop)) != ARK_SUCCESS)
        return fail(ark, err, "ARKStepSetStopTime", flag);
    if (isfinite(base->options.max_step) && base->options.max_step > 0 &&
        (flag = ARKStepSetMaxStep(ark->arkode, base->options.max_step)) != ARK_SUCCESS)
        return fail(ark, err, "ARKStepSetMaxStep", flag);
    base->t_stop = t_stop;
    return BK_OK;
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    arkode_backend *ark = mem;
    sunrealtype t = 0.0;
    int flag = ARKStepEvolve(ark->arkode, ark->base.t_stop, ark->base.y, &t, ARK_ONE_STEP);
    *t_reached = t;
    memcpy(y, N_VGetArrayPointer(ark->base.y), ark->base.n * sizeof *y);
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
    int flag = ARKStepGetDky(ark->arkode, t, 0, ark->base.work);
    if (flag != ARK_SUCCESS)
        return fail(ark, err, "ARKStepGetDky", flag);
    memcpy(y, N_VGetArrayPointer(ark->base.work), ark->base.n * sizeof *y);
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
    bk_sundials_counters(&ark->base, this_start(ark), c);
}

static void destroy(void *mem)
{
    arkode_backend *ark = mem;
    if (!ark)
        return;
    free_objects(ark);
    bk_sundials_destroy(&ark->base);
}

#define ARKODE_BACKEND(NAME, CREATE, CHECK, DOC)                                                \
    {                                                                                           \
        .name = NAME, .doc = DOC, .create = CREATE, .start = start, .step = step,               \
        .interpolate = interpolate, .last_step = last_step, .root_info = root_info,             \
        .counters = counters, .destroy = destroy, .check_options = CHECK,                       \
    }

const bk_solver_backend bk_solver_arkode_bs23 = ARKODE_BACKEND(
    "arkode_bs23", create_bs23, NULL,
    "ARKODE explicit Bogacki-Shampine 3(2), 4 stages (MATLAB ode23's pair): non-stiff");
const bk_solver_backend bk_solver_arkode_dp45 = ARKODE_BACKEND(
    "arkode_dp45", create_dp45, NULL,
    "ARKODE explicit Dormand-Prince 5(4), 7 stages (MATLAB ode45's pair): non-stiff");
const bk_solver_backend bk_solver_arkode_erk = ARKODE_BACKEND(
    "arkode_erk", create_erk, check_erk,
    "ARKODE explicit Runge-Kutta, Zonneveld 4(3) (ARKStep's default order-4 ERK) or the "
    "[solver] arkode_table chosen: non-stiff");
const bk_solver_backend bk_solver_arkode_dirk = ARKODE_BACKEND(
    "arkode_dirk", create_dirk, check_dirk,
    "ARKODE diagonally implicit Runge-Kutta, ESDIRK 4(3I) 6 stages, L-stable, stiffly accurate "
    "(Kennedy & Carpenter) or the [solver] arkode_table chosen; Newton with dense/band direct "
    "solver: stiff");
const bk_solver_backend bk_solver_arkode_imex = ARKODE_BACKEND(
    "arkode_imex", create_imex, NULL,
    "ARKODE additive ARK4(3)6L[2]SA: friction implicit (Newton, dense/band direct solver), "
    "springs and kinematics explicit");
