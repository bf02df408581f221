/* The part of the CVODE, ARKODE and IDA back-ends that does not depend on the package (see
 * sundials_common.h): context, options and problem, vectors, the dense-or-band linear
 * solver, the error handler's last message, counters over restarts. */
#include "sundials_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>

/* Above this size "auto" picks the band solver (when the layout is banded). */
#define BAND_THRESHOLD 16

int bk_sundials_create(void **mem, size_t size, const char *package, char *(*flag_name)(long int),
                       const bk_solver_options *options, bk_error *err)
{
    bk_sundials_base *base = calloc(1, size);
    if (!base)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s back-end: out of memory", package);
    base->package = package;
    base->flag_name = flag_name;
    base->options = *options;
    base->n_roots = -1;
    if (SUNContext_Create(NULL, &base->ctx) != 0) {
        free(base);
        return BK_FAIL(err, BK_ERR_SOLVER, "%s back-end: SUNContext_Create failed", package);
    }
    *mem = base;
    return BK_OK;
}

void bk_sundials_destroy(bk_sundials_base *base)
{
    SUNContext_Free(&base->ctx);
    free(base);
}

void bk_sundials_capture_message(int error_code, const char *module, const char *function, char *msg,
                                 void *base)
{
    bk_sundials_base *b = base;
    snprintf(b->message, sizeof b->message, "%s (%s, code %d)", msg, function ? function : module,
             error_code);
}

int bk_sundials_fail(const bk_sundials_base *base, bk_error *err, const char *what, int flag)
{
    char *flag_name = base->flag_name(flag); /* malloc'ed by SUNDIALS */
    BK_FAIL(err, BK_ERR_SOLVER, "%s: %s failed (flag %d: %s)%s%s", base->package, what, flag,
            flag_name ? flag_name : "?", base->message[0] ? ": " : "", base->message);
    free(flag_name);
    return BK_ERR_SOLVER;
}

int bk_sundials_no_memory(const bk_sundials_base *base, size_t n, bk_error *err)
{
    return BK_FAIL(err, BK_ERR_NOMEM, "%s: cannot allocate a problem of size %zu", base->package, n);
}

void bk_sundials_begin_start(bk_sundials_base *base, const bk_ode_problem *problem,
                             bk_solver_counters finished)
{
    base->problem = *problem;
    base->message[0] = '\0';
    bk_solver_counters_add(&base->done, &finished);
}

void bk_sundials_counters(const bk_sundials_base *base, bk_solver_counters current,
                          bk_solver_counters *total)
{
    *total = base->done;
    bk_solver_counters_add(total, &current);
}

int bk_sundials_new_vectors(bk_sundials_base *base, size_t n, bk_error *err)
{
    sunindextype len = (sunindextype)n;
    base->y = N_VNew_Serial(len, base->ctx);
    base->atol = N_VNew_Serial(len, base->ctx);
    base->work = N_VNew_Serial(len, base->ctx);
    if (!base->y || !base->atol || !base->work)
        return bk_sundials_no_memory(base, n, err);
    return BK_OK;
}

static int use_band(const bk_sundials_base *base, size_t n)
{
    if (strcmp(base->options.linear_solver, "band") == 0)
        return 1;
    if (strcmp(base->options.linear_solver, "dense") == 0)
        return 0;
    return n > BAND_THRESHOLD && 2 * base->problem.half_bandwidth + 1 < n;
}

int bk_sundials_new_linear_solver(bk_sundials_base *base, size_t n, bk_error *err)
{
    sunindextype len = (sunindextype)n;
    if (use_band(base, n)) {
        sunindextype bw = (sunindextype)base->problem.half_bandwidth;
        base->matrix = SUNBandMatrix(len, bw, bw, base->ctx);
        base->linear_solver = base->matrix ? SUNLinSol_Band(base->y, base->matrix, base->ctx) : NULL;
    } else {
        base->matrix = SUNDenseMatrix(len, len, base->ctx);
        base->linear_solver = base->matrix ? SUNLinSol_Dense(base->y, base->matrix, base->ctx) : NULL;
    }
    if (!base->linear_solver)
        return BK_FAIL(err, BK_ERR_NOMEM, "%s: cannot create the linear solver (n = %zu)", base->package, n);
    return BK_OK;
}

void bk_sundials_free_objects(bk_sundials_base *base)
{
    if (base->linear_solver)
        SUNLinSolFree(base->linear_solver);
    if (base->matrix)
        SUNMatDestroy(base->matrix);
    if (base->y)
        N_VDestroy(base->y);
    if (base->atol)
        N_VDestroy(base->atol);
    if (base->work)
        N_VDestroy(base->work);
    base->linear_solver = NULL;
    base->matrix = NULL;
    base->y = base->atol = base->work = NULL;
    base->n = 0;
    base->n_roots = -1;
}
