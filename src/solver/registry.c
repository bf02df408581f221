/* Maps [solver] method names to back-end tables. */
#include <string.h>

#include "bksim/solver.h"

static const bk_solver_backend *const registered_backends[] = {
    &bk_solver_cvode_adams,
    &bk_solver_cvode_bdf,
    &bk_solver_exact,
    &bk_solver_arkode_bs23,
    &bk_solver_arkode_dp45,
    &bk_solver_arkode_erk,
    &bk_solver_arkode_dirk,
    &bk_solver_arkode_imex,
    &bk_solver_ida,
    &bk_solver_gsl_rk8pd,
    &bk_solver_gsl_rkf45,
    &bk_solver_gsl_msbdf,
    NULL,
};

const bk_solver_backend *const *bk_solver_backends(void) { return registered_backends; }

const bk_solver_backend *bk_solver_backend_find(const char *name)
{
    for (const bk_solver_backend *const *b = registered_backends; *b; ++b)
        if (strcmp((*b)->name, name) == 0)
            return *b;
    return NULL;
}
