/* Internal: what the CVODE, ARKODE and IDA back-ends share, written once.  Each back-end's
 * state opens with a bk_sundials_base (as SUNDIALS's packages share src/sundials), so one
 * allocation holds both and the base's address is the state's; the back-end keeps only its
 * package's memory, calls and adapters. */
#ifndef BKSIM_SUNDIALS_COMMON_H
#define BKSIM_SUNDIALS_COMMON_H

#include <stddef.h>

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nvector.h>

#include "bksim/solver.h"

typedef struct bk_sundials_base {
    const char *package;              /* "CVODE", "ARKODE" or "IDA": opens every message */
    char *(*flag_name)(long int flag); /* CVodeGetReturnFlagName, ARKStep..., IDA... */
    bk_solver_options options;
    SUNContext ctx;
    bk_ode_problem problem;           /* of the current start */
    N_Vector y, atol, work;
    SUNMatrix matrix;                 /* implicit methods only */
    SUNLinearSolver linear_solver;
    size_t n;                         /* size the package's objects were built for */
    int n_roots;                      /* size RootInit was called with */
    double t_stop;
    bk_solver_counters done;          /* counters of finished starts */
    char message[512];                /* last message from the package's error handler */
} bk_sundials_base;

/* *mem = a zeroed state of `size` bytes opening with a base, its context created. */
int bk_sundials_create(void **mem, size_t size, const char *package, char *(*flag_name)(long int),
                       const bk_solver_options *options, bk_error *err);
/* Frees the context and the whole state; the back-end has freed its own objects first. */
void bk_sundials_destroy(bk_sundials_base *base);

/* The package's error handler, registered with the base as its user data. */
void bk_sundials_capture_message(int error_code, const char *module, const char *function, char *msg,
                                 void *base);
/* "PACKAGE: what failed (flag F: NAME): last message"; returns BK_ERR_SOLVER. */
int bk_sundials_fail(const bk_sundials_base *base, bk_error *err, const char *what, int flag);
/* "PACKAGE: cannot allocate a problem of size n"; returns BK_ERR_NOMEM. */
int bk_sundials_no_memory(const bk_sundials_base *base, size_t n, bk_error *err);

/* Opens a start: the problem copied, the last message cleared, and the counters of the
 * start that ends here (as the package reports them) added to done. */
void bk_sundials_begin_start(bk_sundials_base *base, const bk_ode_problem *problem,
                             bk_solver_counters finished);
/* *total = the finished starts' counters plus the current start's. */
void bk_sundials_counters(const bk_sundials_base *base, bk_solver_counters current,
                          bk_solver_counters *total);

/* y, atol and work, of size n. */
int bk_sundials_new_vectors(bk_sundials_base *base, size_t n, bk_error *err);
/* The dense or band matrix and direct solver for n unknowns, by [solver] linear_solver. */
int bk_sundials_new_linear_solver(bk_sundials_base *base, size_t n, bk_error *err);
/* Frees what the two above made and forgets the size and the root count; after the
 * package's memory, which refers to them. */
void bk_sundials_free_objects(bk_sundials_base *base);

#endif
