/* Maps [solver] method names to back-end tables. */
#include <string.h>

#include "bksim/solver.h"

static const bk_solver_backend *const registered_backends[] = {
    &bk_solver_cvode_adams,
    &bk_solver_cvode_bdf,
    &bk_solver_exact,
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
