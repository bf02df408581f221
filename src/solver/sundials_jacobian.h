/* Internal: the problem's exact Jacobian into a SUNDIALS dense or band matrix. */
#ifndef BKSIM_SUNDIALS_JACOBIAN_H
#define BKSIM_SUNDIALS_JACOBIAN_H

#include <sundials/sundials_matrix.h>

#include "bksim/solver.h"

/* matrix = scale * J + diagonal * D with J = d(ydot)/dy at (t, y) and D = diag of the
 * problem's differential_id (I for an ODE); a band matrix keeps only the entries inside its
 * band.  CVODE and ARKODE use (1, 0), IDA (-1, cj).  Returns the problem's jacobian status. */
int bk_sundials_jacobian(const bk_ode_problem *problem, double t, const double *y, SUNMatrix matrix,
                         double scale, double diagonal);

#endif
