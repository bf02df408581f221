/* The problem's exact Jacobian into SUNDIALS matrices (see sundials_jacobian.h). */
#include "sundials_jacobian.h"

#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>

typedef struct target {
    SUNMatrix matrix;
    int band;
    long upper, lower; /* band widths */
    double scale;
} target;

static void put_entry(void *self, size_t row, size_t col, double value)
{
    target *j = self;
    sunindextype r = (sunindextype)row, c = (sunindextype)col;
    if (!j->band)
        SM_ELEMENT_D(j->matrix, r, c) += j->scale * value;
    else if ((long)col - (long)row <= j->upper && (long)row - (long)col <= j->lower)
        SM_ELEMENT_B(j->matrix, r, c) += j->scale * value;
}

int bk_sundials_jacobian(const bk_ode_problem *problem, double t, const double *y, SUNMatrix matrix,
                         double scale, double diagonal)
{
    SUNMatZero(matrix);
    target j = {matrix, SUNMatGetID(matrix) == SUNMATRIX_BAND, 0, 0, scale};
    if (j.band) {
        j.upper = (long)SM_UBAND_B(matrix);
        j.lower = (long)SM_LBAND_B(matrix);
    }
    int rc = problem->jacobian(t, y, problem->user, put_entry, &j);
    if (diagonal != 0.0) {
        const double *id = problem->differential_id;
        sunindextype n = j.band ? SM_COLUMNS_B(matrix) : SM_COLUMNS_D(matrix);
        for (sunindextype k = 0; k < n; ++k) {
            if (id && id[k] == 0.0)
                continue; /* an algebraic row has no y' term */
            if (j.band)
                SM_ELEMENT_B(matrix, k, k) += diagonal;
            else
                SM_ELEMENT_D(matrix, k, k) += diagonal;
        }
    }
    return rc;
}
