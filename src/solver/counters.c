/* What every back-end shares: adding up its work counters (steps, right-hand sides, root
 * functions, failed error tests, nonlinear iterations) across instances. */
#include "bksim/solver.h"

void bk_solver_counters_add(bk_solver_counters *sum, const bk_solver_counters *more)
{
    sum->steps += more->steps;
    sum->rhs_evals += more->rhs_evals;
    sum->root_evals += more->root_evals;
    sum->err_test_fails += more->err_test_fails;
    sum->nonlin_iters += more->nonlin_iters;
}
