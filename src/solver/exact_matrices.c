/* The exact stepper reads its problem: the affine forcing at the start and the stiffness,
 * damping, quadrature position and velocity coefficients (K, D, P, Q), from the problem's
 * exact Jacobian when it has one (O(p) entries, checked by one combined right-hand-side
 * probe), else one probe per column; anything that is not affine with constant coefficients
 * is refused, but for the dashpots' dissipation v^T C v (C = M D) when the problem declares
 * it, which is checked against D instead. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "exact_backend.h"

static int add_coupling(exact_backend *eb, size_t row, size_t col, double value)
{
    if (bk_exact_reserve_coupling(eb) != 0)
        return -1;
    eb->shared->couplings[eb->n_couplings++] = (coupling){row, col, value};
    return 0;
}

static int add_damping(exact_backend *eb, size_t row, size_t col, double value)
{
    if (bk_exact_reserve_damping(eb) != 0)
        return -1;
    eb->shared->dampings[eb->n_dampings++] = (coupling){row, col, value};
    return 0;
}

/* v^T C v, C = M D: the dissipation rate the dashpots' quadrature must have at velocities
 * v (of the pairs, stride 2 in a state vector). */
static double dissipation_rate(const exact_backend *eb, const double *y)
{
    double sum = 0.0;
    for (size_t e = 0; e < eb->n_dampings; ++e) {
        const coupling *cp = &eb->shared->dampings[e];
        sum += eb->problem.pair_mass[cp->row] * cp->value * y[2 * cp->row + 1] * y[2 * cp->col + 1];
    }
    return sum;
}

/* Its size for a tolerance: the sum of the magnitudes of its terms. */
static double dissipation_scale(const exact_backend *eb, const double *y)
{
    double sum = 0.0;
    for (size_t e = 0; e < eb->n_dampings; ++e) {
        const coupling *cp = &eb->shared->dampings[e];
        sum += fabs(eb->problem.pair_mass[cp->row] * cp->value * y[2 * cp->row + 1] * y[2 * cp->col + 1]);
    }
    return sum;
}

static int check_dissipation(const exact_backend *eb, const double *y, double rate, bk_error *err)
{
    double expected = dissipation_rate(eb, y);
    if (fabs(rate - expected) > STRUCTURE_TOL * dissipation_scale(eb, y) + DBL_MIN)
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact: the last component's rate is not the dashpots' dissipation "
                       "v^T C v the damping of the accelerations gives (%.17g vs %.17g)" USE_INTEGRATOR,
                       rate, expected);
    return BK_OK;
}

/* --- start: read the matrices, split into clusters, diagonalise -------------------------- */

static int call_rhs(exact_backend *eb, double t, const double *y, double *ydot, bk_error *err)
{
    eb->counters.rhs_evals++;
    int rc = eb->problem.rhs(t, y, ydot, eb->problem.user);
    if (rc != 0)
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "exact stepper: the right-hand side failed (code %d) at t = %.17g s", rc, t);
    for (size_t k = 0; k < eb->n; ++k)
        if (!isfinite(ydot[k]))
            return BK_FAIL(err, BK_ERR_NUMERIC,
                           "exact stepper: non-finite right-hand side (component %zu) at t = %.17g s",
                           k, t);
    return BK_OK;
}

static int check_kinematics(const exact_backend *eb, const double *y, const double *ydot, bk_error *err)
{
    for (size_t i = 0; i < eb->p; ++i) {
        double v = y[2 * i + 1];
        if (fabs(ydot[2 * i] - v) > 8.0 * DBL_EPSILON * fabs(v))
            return BK_FAIL(err, BK_ERR_CONFIG,
                           "method exact: the rate of position %zu is not its velocity; the state "
                           "must be (position, velocity) pairs followed by quadratures" USE_INTEGRATOR,
                           i);
    }
    return BK_OK;
}

static int rhs_checked(exact_backend *eb, double t, const double *y, double *ydot, bk_error *err)
{
    int rc = call_rhs(eb, t, y, ydot, err);
    return rc != BK_OK ? rc : check_kinematics(eb, y, ydot, err);
}

static int refuse_quadrature(size_t component, size_t quadrature, bk_error *err)
{
    return BK_FAIL(err, BK_ERR_CONFIG,
                   "method exact: component %zu's rate depends on component %zu, which should be a "
                   "quadrature" USE_INTEGRATOR,
                   component, quadrature);
}

/* A perturbation of component `k` of y0 that is exactly representable as a difference. */
static double perturb(exact_backend *eb, size_t k)
{
    memcpy(eb->scratch, eb->y0, eb->n * sizeof *eb->scratch);
    double bumped = eb->y0[k] + (1.0 + fabs(eb->y0[k]));
    eb->scratch[k] = bumped;
    return bumped - eb->y0[k];
}

/* The rates at the start and the forcing's time rate; scale = the size of both. */
static int probe_forcing(exact_backend *eb, bk_error *err)
{
    const double *f0 = eb->f0;
    size_t n = eb->n, p = eb->p, m = eb->m;
    double t0 = eb->t0, *f = eb->probe;
    int rc;
    if ((rc = rhs_checked(eb, t0, eb->y0, eb->f0, err)) != BK_OK)
        return rc;
    for (size_t i = 0; i < p; ++i)
        eb->accel0[i] = f0[2 * i + 1];
    for (size_t j = 0; j < m; ++j)
        eb->qdot0[j] = f0[2 * p + j];
    double dt = (t0 + (1.0 + fabs(t0))) - t0;
    if ((rc = rhs_checked(eb, t0 + dt, eb->y0, f, err)) != BK_OK)
        return rc;
    for (size_t k = 0; k < n; ++k)
        eb->scale[k] = fabs(f0[k]) + fabs(f[k] - f0[k]);
    for (size_t i = 0; i < p; ++i)
        eb->accel_rate[i] = (f[2 * i + 1] - f0[2 * i + 1]) / dt;
    for (size_t j = 0; j < m; ++j)
        eb->q_rate[j] = (f[2 * p + j] - f0[2 * p + j]) / dt;
    if (eb->dissipation) /* computed from the modes' energy balance instead */
        eb->qdot0[m - 1] = eb->q_rate[m - 1] = 0.0;
    return BK_OK;
}

/* Without a Jacobian: K, P and Q off the right-hand side, one probe per component (O(p)
 * probes of O(p) each). */
static int probe_columns(exact_backend *eb, bk_error *err)
{
    const double *f0 = eb->f0;
    size_t n = eb->n, p = eb->p, m = eb->m;
    double t0 = eb->t0;
    double *f = eb->probe, *scale = eb->scale;
    int rc;
    /* Positions: columns of K and of P. */
    for (size_t l = 0; l < p; ++l) {
        double h = perturb(eb, 2 * l);
        if ((rc = rhs_checked(eb, t0, eb->scratch, f, err)) != BK_OK)
            return rc;
        for (size_t i = 0; i < p; ++i) {
            double delta = f[2 * i + 1] - f0[2 * i + 1];
            if (delta != 0.0 && add_coupling(eb, i, l, -delta / h) != 0)
                return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the couplings");
            scale[2 * i + 1] += fabs(delta);
        }
        for (size_t j = 0; j < m; ++j) {
            double delta = f[2 * p + j] - f0[2 * p + j];
            eb->P[j * p + l] = delta / h;
            scale[2 * p + j] += fabs(delta);
        }
        /* the dissipation must not move with a position (D is not known yet, but its value
         * at these velocities is the one at the start) */
        if (eb->dissipation && fabs(f[n - 1] - f0[n - 1]) > STRUCTURE_TOL * (fabs(f0[n - 1]) + DBL_MIN))
            return BK_FAIL(err, BK_ERR_CONFIG,
                           "method exact: the last component's rate, declared the dashpots' "
                           "dissipation, depends on position %zu" USE_INTEGRATOR, l);
    }
    /* Velocities: columns of D (dashpots) and of Q; the dissipation's rates at these probes
     * kept (in delta) for its check once D is complete. */
    size_t affine_m = m - (size_t)eb->dissipation;
    for (size_t l = 0; l < p; ++l) {
        double h = perturb(eb, 2 * l + 1);
        if ((rc = rhs_checked(eb, t0, eb->scratch, f, err)) != BK_OK)
            return rc;
        for (size_t i = 0; i < p; ++i) {
            double delta = f[2 * i + 1] - f0[2 * i + 1];
            if (fabs(delta) > STRUCTURE_TOL * scale[2 * i + 1] && add_damping(eb, i, l, -delta / h) != 0)
                return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the dashpots");
        }
        for (size_t j = 0; j < affine_m; ++j) {
            double delta = f[2 * p + j] - f0[2 * p + j];
            eb->Q[j * p + l] = delta / h;
            scale[2 * p + j] += fabs(delta);
        }
        if (eb->dissipation)
            eb->delta[l] = f[n - 1];
    }
    if (eb->dissipation) {
        if ((rc = check_dissipation(eb, eb->y0, f0[n - 1], err)) != BK_OK)
            return rc;
        for (size_t l = 0; l < p && rc == BK_OK; ++l) {
            perturb(eb, 2 * l + 1);
            rc = check_dissipation(eb, eb->scratch, eb->delta[l], err);
        }
        if (rc != BK_OK)
            return rc;
        memset(&eb->P[(m - 1) * p], 0, p * sizeof *eb->P);
    }
    /* Quadratures: nothing may depend on them. */
    for (size_t j = 0; j < m; ++j) {
        perturb(eb, 2 * p + j);
        if ((rc = rhs_checked(eb, t0, eb->scratch, f, err)) != BK_OK)
            return rc;
        for (size_t k = 0; k < n; ++k)
            if ((k % 2 == 1 || k >= 2 * p) && fabs(f[k] - f0[k]) > STRUCTURE_TOL * scale[k])
                return refuse_quadrature(k, 2 * p + j, err);
    }
    return BK_OK;
}

/* The Jacobian's put(): K into couplings, D into dampings, P and Q; position rows are left
 * to the kinematics check of the verifying probe, and the dissipation's row (its gradient at
 * y0, not a constant) to that probe's check of v^T C v. */
static void put_entry(void *matrix, size_t row, size_t col, double value)
{
    exact_backend *eb = matrix;
    size_t p = eb->p;
    if (eb->jacobian_status != JACOBIAN_OK || value == 0.0)
        return;
    int status = JACOBIAN_OK;
    if (row >= eb->n || col >= eb->n)
        status = JACOBIAN_RANGE;
    else if (row < 2 * p && row % 2 == 0)
        return;
    else if (eb->dissipation && row == eb->n - 1 && col < 2 * p)
        return;
    else if (col >= 2 * p)
        status = JACOBIAN_QUADRATURE;
    else if (row < 2 * p && col % 2 == 1)
        status = add_damping(eb, row / 2, col / 2, -value) == 0 ? JACOBIAN_OK : JACOBIAN_NOMEM;
    else if (row < 2 * p)
        status = add_coupling(eb, row / 2, col / 2, -value) == 0 ? JACOBIAN_OK : JACOBIAN_NOMEM;
    else
        (col % 2 == 0 ? eb->P : eb->Q)[(row - 2 * p) * p + col / 2] += value;
    if (status != JACOBIAN_OK) {
        eb->jacobian_status = status;
        eb->bad_row = row;
        eb->bad_col = col;
    }
}

/* With a Jacobian: K, P and Q from its entries, then one probe moving every component at
 * once must give the rates the entries predict (the problem's promise that it is affine and
 * the Jacobian exact, checked). */
static int read_jacobian(exact_backend *eb, bk_error *err)
{
    const double *f0 = eb->f0;
    size_t n = eb->n, p = eb->p, m = eb->m;
    eb->jacobian_status = JACOBIAN_OK;
    int rc = eb->problem.jacobian(eb->t0, eb->y0, eb->problem.user, put_entry, eb);
    if (rc != 0)
        return BK_FAIL(err, BK_ERR_SOLVER, "exact stepper: the Jacobian failed (code %d) at t = %.17g s",
                       rc, eb->t0);
    switch (eb->jacobian_status) {
    case JACOBIAN_NOMEM:
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the couplings");
    case JACOBIAN_RANGE:
        return BK_FAIL(err, BK_ERR_SOLVER, "exact stepper: Jacobian entry (%zu, %zu) outside the %zu "
                       "components", eb->bad_row, eb->bad_col, n);
    case JACOBIAN_QUADRATURE:
        return refuse_quadrature(eb->bad_row, eb->bad_col, err);
    default:
        break;
    }
    /* Distinct weights, so that no dependence the entries miss can cancel out. */
    double *delta = eb->delta, *predicted = eb->predicted, *size = eb->scale;
    for (size_t k = 0; k < n; ++k) {
        double bumped = eb->y0[k] + (1.0 + fabs(eb->y0[k])) * (1.0 + 0.25 * (double)(k % 4));
        eb->scratch[k] = bumped;
        delta[k] = bumped - eb->y0[k];
        predicted[k] = f0[k];
        size[k] = fabs(f0[k]);
    }
    for (size_t e = 0; e < eb->n_couplings; ++e) {
        const coupling *cp = &eb->shared->couplings[e];
        double change = -cp->value * delta[2 * cp->col];
        predicted[2 * cp->row + 1] += change;
        size[2 * cp->row + 1] += fabs(change);
    }
    for (size_t e = 0; e < eb->n_dampings; ++e) {
        const coupling *cp = &eb->shared->dampings[e];
        double change = -cp->value * delta[2 * cp->col + 1];
        predicted[2 * cp->row + 1] += change;
        size[2 * cp->row + 1] += fabs(change);
    }
    for (size_t j = 0; j < m; ++j)
        for (size_t l = 0; l < p; ++l) {
            double change = eb->P[j * p + l] * delta[2 * l] + eb->Q[j * p + l] * delta[2 * l + 1];
            predicted[2 * p + j] += change;
            size[2 * p + j] += fabs(eb->P[j * p + l] * delta[2 * l]) +
                               fabs(eb->Q[j * p + l] * delta[2 * l + 1]);
        }
    double *f = eb->probe;
    if ((rc = rhs_checked(eb, eb->t0, eb->scratch, f, err)) != BK_OK)
        return rc;
    if (eb->dissipation && ((rc = check_dissipation(eb, eb->y0, f0[n - 1], err)) != BK_OK ||
                            (rc = check_dissipation(eb, eb->scratch, f[n - 1], err)) != BK_OK))
        return rc;
    for (size_t k = 0; k < n - (size_t)eb->dissipation; ++k) {
        if (k < 2 * p && k % 2 == 0)
            continue;
        if (fabs(f[k] - predicted[k]) > STRUCTURE_TOL * (size[k] + fabs(f[k] - f0[k])))
            return BK_FAIL(err, BK_ERR_CONFIG,
                           "method exact: the rate of component %zu is not the affine function "
                           "its Jacobian gives (%.17g vs %.17g)" USE_INTEGRATOR,
                           k, f[k], predicted[k]);
    }
    return BK_OK;
}


int bk_exact_read_problem(exact_backend *eb, bk_error *err)
{
    int rc = probe_forcing(eb, err);
    if (rc == BK_OK)
        rc = eb->problem.jacobian ? read_jacobian(eb, err) : probe_columns(eb, err);
    return rc;
}
