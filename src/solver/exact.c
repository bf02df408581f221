/* Exact piecewise-analytic stepper for affine problems (Coulomb friction, linear or frozen
 * tension-only springs, a constant-velocity driver).
 *
 * What it computes.  Between two (re)starts the problem handed over is
 *
 *     xi'' = -K xi + a(t)          p pairs (xi, v = xi'), K = M^-1 (stiffness), constant
 *     q'   = P xi + Q v + r(t)     quadratures (energy increments)
 *
 * with a and r affine in t.  start() reads K, P, Q and the affine forcing (measured from the
 * starting state, so that u = xi - xi0 starts at 0), splits the pairs into clusters (the
 * connected components of K's coupling), symmetrises each cluster's S = M^(1/2) K M^(-1/2)
 * and diagonalises it, S = U diag(w_k^2) U^T (GSL).  In the modal coordinates
 * eta = U^T M^(1/2) u each mode is an undamped oscillator with a ramp force, tau = t - t0:
 *
 *     eta_k'' = -w_k^2 eta_k + g_k + d_k tau,   eta_k(0) = 0,  eta_k'(0) = c_k
 *     eta_k   = c_k phi1 + g_k phi2 + d_k phi3,  eta_k' - c_k = -w_k^2 c_k phi2 + g_k phi1 + d_k phi2
 *
 * where phi0 = cos(w tau), phi1 = sin(w tau)/w, and phi_{j+1} is the integral of phi_j from 0,
 * so phi2 = (1 - cos)/w^2 = 2 sin^2(w tau / 2)/w^2, phi3 = (tau - phi1)/w^2,
 * phi4 = (tau^2/2 - phi2)/w^2; for w tau < 2 phi3 and phi4 come from their power series,
 * and w = 0 (or w^2 within rounding of zero relative to the cluster's largest) gives
 * tau^j / j!.  The quadratures are the integrals of their affine rates along this solution,
 * again sums of phi2..phi4, in closed form.  Every evaluation of y(t) is exact up to rounding;
 * nothing is integrated, so there is no truncation error at all.
 *
 * Root functions are sampled along the exact solution at most every 1/16 of the shortest
 * modal period (and max_step); a sign change is located by GSL's Brent on the exact solution
 * to the last few representable doubles and reported with the state just after the crossing,
 * as CVODE does.  A function exactly zero at the start stays inactive until it moves away
 * from zero (CVODE's convention).  A long island can have several transitions per sampling
 * step, and every probe evaluates all its root functions, so the number of probes per
 * transition is what must stay bounded: a step with several crossings is first halved toward
 * the earliest, then one function is located and the others sorted by two evaluations
 * around its root (find_roots).
 *
 * Why.  It is the accuracy yardstick for the integrators (transition times to ~1e-15
 * relative, including case C's grazing stops that no tolerance-driven integrator resolves)
 * and, with a few dozen root evaluations per slip, the fastest method for Coulomb scenes.
 *
 * Why clusters.  Stuck blocks are fixed, so the slipping blocks an island integrates form
 * independent short stretches even when many slip at once.  Decomposing the whole p x p
 * matrix would cost O(p^3) per restart and every root probe O(p^2); per cluster the
 * decomposition costs sum p_i^2 and a probe sum p_i^2 + O(p), and the eigenvectors are
 * exactly those of the block-diagonal matrix, so nothing is approximated.  A chain stretch's
 * S is tridiagonal, and LAPACK's dstevr (relatively robust representations) diagonalises it
 * in O(p^2); only a ring slipping all round (cyclic S) goes through GSL's dense symmv, p^3.
 * K, P and Q come from the problem's exact Jacobian when it has one (O(p) entries, checked
 * against the right-hand side by one combined probe) instead of one right-hand-side probe
 * per component, which is O(p^2).
 *
 * Why uniform clusters are special.  Blocks of equal mass, equal velocity and equal
 * acceleration whose stiffness rows sum alike (a uniform chain slipping together, its
 * couplings exactly balanced) move as one: their motion is the single oscillator of that
 * row sum.  The eigenvectors of such a cluster are exact only up to rounding, and summing
 * the modes back would give each block a slightly different motion, so a uniform chain
 * that physically slides as one would break into sub-events (seen: 3,393 transitions where
 * the integrators give 41 synchronous slips of 16 blocks).  So a uniform cluster is solved
 * as that one oscillator and every member gets the same numbers: symmetric inputs give
 * symmetric outputs, and the cost is O(p) however long the cluster. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_vector.h>
#include <lapacke.h>

#include "bksim/solver.h"

#define PI 3.14159265358979323846
#define SAMPLES_PER_PERIOD 16.0
/* An eigenvalue of S below this fraction of its cluster's largest is rounding: the mode is
 * free. */
#define ZERO_MODE (128.0 * DBL_EPSILON)
/* Relative size of a structural entry that must vanish (velocity dependence etc.). */
#define STRUCTURE_TOL 1e-9
#define BRENT_MAX_ITER 200
#define MAX_HALVINGS 16
#define USE_INTEGRATOR "; use method = auto (it picks an integrator for such scenes), gsl_rk8pd or cvode_bdf"
/* Stiffness coupling K[row][col] (s^-2) between pairs, one Jacobian entry or probe column;
 * entries for one (row, col) add up. */
typedef struct coupling {
    size_t row, col;
    double value;
} coupling;

/* A problem the Jacobian shows the stepper cannot solve (first offending entry). */
enum { JACOBIAN_OK, JACOBIAN_NOMEM, JACOBIAN_RANGE, JACOBIAN_VELOCITY, JACOBIAN_QUADRATURE };

typedef struct exact_backend {
    bk_solver_options options;
    bk_ode_problem problem;
    size_t n, p, m, n_roots;    /* state size, pairs, quadratures, root functions */
    double t0, t_stop, h;       /* start, stop, sampling step */
    double t_now;               /* time reached by the last step */
    double t_lo, t_hi;          /* the last step */

    /* One arena for everything sized by p, m and n; regrown only when it must. */
    double *arena;
    size_t arena_cap;
    double *y0;                 /* n: the starting state */
    double *f0, *scratch, *probe, *scale, *delta, *predicted; /* n each: rates at the start,
                                                                 work space */
    double *sqrt_mass;          /* p */
    double *omega2, *omega;     /* p, by mode (a cluster's modes follow its first's) */
    double *c, *g, *d;          /* p: modal initial velocity, forcing, forcing rate */
    double *eta, *deta, *ieta, *idv; /* p: eta, eta' - c, their integrals */
    double *accel0, *accel_rate;/* p: accelerations at t0 and their time rate */
    double *row_sum, *row_scale;/* p: sum and largest magnitude of each row of K */
    double *P, *Q;              /* m*p: quadrature rates' position and velocity coefficients */
    double *P_modal, *Q_modal;  /* m*p: the same in modal coordinates */
    double *qdot0, *q_rate;     /* m: quadrature rates at t0 and their time rate */

    /* Clusters: cluster k holds pairs members[first[k] .. first[k + 1]) in ascending order,
     * its modes are first[k] .. first[k + 1], its matrices start at offset[k]. */
    size_t *indices;
    size_t indices_cap;
    size_t *members, *first, *offset, *cluster_of, *local, *parent; /* p (+1) each */
    size_t *uniform;            /* per cluster: it moves as one (see the top of the file) */
    size_t n_clusters;
    coupling *couplings;        /* K's entries */
    size_t n_couplings, couplings_cap;
    double *matrices;           /* S of each cluster (in place), then T = M^(-1/2) U of each,
                                   then one cluster's work copy */
    size_t matrices_cap;
    double *S, *T, *work;
    gsl_eigen_symmv_workspace *eigen;
    int jacobian_status;
    size_t bad_row, bad_col;

    /* Root functions. */
    size_t roots_cap;
    int *direction;
    signed char *sign;          /* last non-zero sign seen; 0 = inactive (zero so far) */
    int *found;
    double *g_hi, *g_try, *root_t;
    double g_try_time;          /* when g_try was evaluated (NAN: not since the start) */
    gsl_root_fsolver *brent;

    bk_solver_counters counters;
} exact_backend;

/* --- the modal basis functions ---------------------------------------------------------- */

/* phi[1..4] at tau for angular frequency w >= 0 (see the header; phi0 never enters y). */
static void basis(double w, double tau, double phi[5])
{
    double x = w * tau;
    double tau2 = tau * tau;
    if (w == 0.0) {
        phi[1] = tau;
        phi[2] = 0.5 * tau2;
        phi[3] = tau2 * tau / 6.0;
        phi[4] = tau2 * tau2 / 24.0;
        return;
    }
    double w2 = w * w, half = sin(0.5 * x);
    phi[1] = sin(x) / w;
    phi[2] = 2.0 * half * half / w2;
    if (fabs(x) >= 2.0) {
        phi[3] = (tau - phi[1]) / w2;
        phi[4] = (0.5 * tau2 - phi[2]) / w2;
        return;
    }
    /* sum_m (-x^2)^m / (j + 2m)!, j = 3, 4: alternating, terms below 1/j! from the start. */
    double z = x * x;
    for (int j = 3; j <= 4; ++j) {
        double term = j == 3 ? 1.0 / 6.0 : 1.0 / 24.0, sum = term;
        for (int k = 0; k < 40 && fabs(term) > 1e-18 * fabs(sum); ++k) {
            term *= -z / (double)((j + 2 * k + 1) * (j + 2 * k + 2));
            sum += term;
        }
        phi[j] = (j == 3 ? tau2 * tau : tau2 * tau2) * sum;
    }
}

/* The exact state at time t into y (size n): O(p) modes, O(sum p_i^2) back to the pairs. */
static void exact_state(exact_backend *eb, double t, double *y)
{
    size_t p = eb->p, m = eb->m;
    double tau = t - eb->t0;
    for (size_t k = 0; k < p; ++k) {
        double ck = eb->c[k], gk = eb->g[k], dk = eb->d[k];
        if (ck == 0.0 && gk == 0.0 && dk == 0.0) { /* idle (all but one mode of a uniform cluster) */
            eb->eta[k] = eb->deta[k] = eb->ieta[k] = eb->idv[k] = 0.0;
            continue;
        }
        double phi[5], w2 = eb->omega2[k];
        basis(eb->omega[k], tau, phi);
        eb->eta[k] = ck * phi[1] + gk * phi[2] + dk * phi[3];
        eb->deta[k] = -w2 * ck * phi[2] + gk * phi[1] + dk * phi[2];
        eb->ieta[k] = ck * phi[2] + gk * phi[3] + dk * phi[4];
        eb->idv[k] = (dk - w2 * ck) * phi[3] + gk * phi[2];
    }
    for (size_t cl = 0; cl < eb->n_clusters; ++cl) {
        size_t first = eb->first[cl], size = eb->first[cl + 1] - first;
        const double *T = &eb->T[eb->offset[cl]];
        const double *eta = &eb->eta[first], *deta = &eb->deta[first];
        if (eb->uniform[cl]) {
            for (size_t r = 0; r < size; ++r) {
                size_t i = eb->members[first + r];
                y[2 * i] = eb->y0[2 * i] + eta[0];
                y[2 * i + 1] = eb->y0[2 * i + 1] + deta[0];
            }
            continue;
        }
        for (size_t r = 0; r < size; ++r) {
            const double *Tr = &T[r * size];
            double u = 0.0, dv = 0.0;
            for (size_t k = 0; k < size; ++k) {
                u += Tr[k] * eta[k];
                dv += Tr[k] * deta[k];
            }
            size_t i = eb->members[first + r];
            y[2 * i] = eb->y0[2 * i] + u;
            y[2 * i + 1] = eb->y0[2 * i + 1] + dv;
        }
    }
    for (size_t j = 0; j < m; ++j) {
        const double *Pj = &eb->P_modal[j * p], *Qj = &eb->Q_modal[j * p];
        double sum = 0.0;
        for (size_t k = 0; k < p; ++k)
            sum += Pj[k] * eb->ieta[k] + Qj[k] * eb->idv[k];
        y[2 * p + j] = eb->y0[2 * p + j] + (eb->qdot0[j] + 0.5 * eb->q_rate[j] * tau) * tau + sum;
    }
}

/* --- memory ----------------------------------------------------------------------------- */

static int reserve(exact_backend *eb, size_t n, size_t p, size_t m, size_t n_roots, bk_error *err)
{
    size_t need = 7 * n + 14 * p + 4 * m * p + 2 * m + 1;
    if (need > eb->arena_cap) {
        double *grown = malloc(need * sizeof *grown);
        if (!grown)
            return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for %zu components", n);
        free(eb->arena);
        eb->arena = grown;
        eb->arena_cap = need;
    }
    double *a = eb->arena;
    eb->y0 = a, a += n;
    eb->f0 = a, a += n;
    eb->scratch = a, a += n;
    eb->probe = a, a += n;
    eb->scale = a, a += n;
    eb->delta = a, a += n;
    eb->predicted = a, a += n;
    eb->sqrt_mass = a, a += p;
    eb->omega2 = a, a += p;
    eb->omega = a, a += p;
    eb->c = a, a += p;
    eb->g = a, a += p;
    eb->d = a, a += p;
    eb->eta = a, a += p;
    eb->deta = a, a += p;
    eb->ieta = a, a += p;
    eb->idv = a, a += p;
    eb->accel0 = a, a += p;
    eb->accel_rate = a, a += p;
    eb->row_sum = a, a += p;
    eb->row_scale = a, a += p;
    eb->P = a, a += m * p;
    eb->Q = a, a += m * p;
    eb->P_modal = a, a += m * p;
    eb->Q_modal = a, a += m * p;
    eb->qdot0 = a, a += m;
    eb->q_rate = a;

    size_t need_indices = 7 * (p + 1);
    if (need_indices > eb->indices_cap) {
        size_t *grown = malloc(need_indices * sizeof *grown);
        if (!grown)
            return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for %zu pairs", p);
        free(eb->indices);
        eb->indices = grown;
        eb->indices_cap = need_indices;
    }
    size_t *ix = eb->indices;
    eb->members = ix, ix += p + 1;
    eb->first = ix, ix += p + 1;
    eb->offset = ix, ix += p + 1;
    eb->cluster_of = ix, ix += p + 1;
    eb->local = ix, ix += p + 1;
    eb->uniform = ix, ix += p + 1;
    eb->parent = ix;

    if (n_roots > eb->roots_cap) {
        free(eb->direction);
        free(eb->sign);
        free(eb->found);
        free(eb->g_hi);
        eb->direction = malloc(n_roots * sizeof *eb->direction);
        eb->sign = malloc(n_roots * sizeof *eb->sign);
        eb->found = malloc(n_roots * sizeof *eb->found);
        eb->g_hi = malloc(3 * n_roots * sizeof *eb->g_hi);
        eb->roots_cap = 0;
        if (!eb->direction || !eb->sign || !eb->found || !eb->g_hi)
            return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for %zu root functions",
                           n_roots);
        eb->roots_cap = n_roots;
    }
    if (eb->g_hi) {
        eb->g_try = eb->g_hi + eb->roots_cap;
        eb->root_t = eb->g_try + eb->roots_cap;
    }
    return BK_OK;
}

/* Room for the clusters' S and T (`total` doubles each) and one work copy of `largest`^2. */
static int reserve_matrices(exact_backend *eb, size_t total, size_t largest, bk_error *err)
{
    size_t need = 2 * total + largest * largest + 3 * largest + 1;
    if (need > eb->matrices_cap) {
        double *grown = malloc(need * sizeof *grown);
        if (!grown)
            return BK_FAIL(err, BK_ERR_NOMEM,
                           "exact stepper: out of memory for the modes of %zu pairs", eb->p);
        free(eb->matrices);
        eb->matrices = grown;
        eb->matrices_cap = need;
    }
    eb->S = eb->matrices;
    eb->T = eb->S + total;
    eb->work = eb->T + total;
    return BK_OK;
}

static int add_coupling(exact_backend *eb, size_t row, size_t col, double value)
{
    if (eb->n_couplings == eb->couplings_cap) {
        size_t cap = eb->couplings_cap ? 2 * eb->couplings_cap : 256;
        coupling *grown = realloc(eb->couplings, cap * sizeof *grown);
        if (!grown)
            return -1;
        eb->couplings = grown;
        eb->couplings_cap = cap;
    }
    eb->couplings[eb->n_couplings++] = (coupling){row, col, value};
    return 0;
}

static int create(void **mem, const bk_solver_options *options, bk_error *err)
{
    exact_backend *eb = calloc(1, sizeof *eb);
    if (!eb)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory");
    eb->options = *options;
    eb->brent = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!eb->brent) {
        free(eb);
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the root finder");
    }
    *mem = eb;
    return BK_OK;
}

static void destroy(void *mem)
{
    exact_backend *eb = mem;
    if (!eb)
        return;
    if (eb->eigen)
        gsl_eigen_symmv_free(eb->eigen);
    gsl_root_fsolver_free(eb->brent);
    free(eb->arena);
    free(eb->indices);
    free(eb->couplings);
    free(eb->matrices);
    free(eb->direction);
    free(eb->sign);
    free(eb->found);
    free(eb->g_hi);
    free(eb);
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

static int call_roots(exact_backend *eb, double t, double *g, bk_error *err)
{
    if (eb->n_roots == 0)
        return BK_OK;
    exact_state(eb, t, eb->scratch);
    eb->counters.root_evals++;
    int rc = eb->problem.roots(t, eb->scratch, g, eb->problem.user);
    if (rc != 0)
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "exact stepper: the root functions failed (code %d) at t = %.17g s", rc, t);
    for (size_t i = 0; i < eb->n_roots; ++i)
        if (isnan(g[i]))
            return BK_FAIL(err, BK_ERR_NUMERIC,
                           "exact stepper: root function %zu is NaN at t = %.17g s", i, t);
    return BK_OK;
}

/* A position's rate must be its velocity. */
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

static int refuse_velocity(size_t pair, size_t velocity_of, bk_error *err)
{
    return BK_FAIL(err, BK_ERR_CONFIG,
                   "method exact: the acceleration of pair %zu depends on the velocity of pair %zu "
                   "(velocity-dependent friction or damping); it needs Coulomb friction (constant "
                   "sliding force, no friction state)" USE_INTEGRATOR,
                   pair, velocity_of);
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
    }
    /* Velocities: accelerations must not depend on them; columns of Q. */
    for (size_t l = 0; l < p; ++l) {
        double h = perturb(eb, 2 * l + 1);
        if ((rc = rhs_checked(eb, t0, eb->scratch, f, err)) != BK_OK)
            return rc;
        for (size_t i = 0; i < p; ++i)
            if (fabs(f[2 * i + 1] - f0[2 * i + 1]) > STRUCTURE_TOL * scale[2 * i + 1])
                return refuse_velocity(i, l, err);
        for (size_t j = 0; j < m; ++j) {
            double delta = f[2 * p + j] - f0[2 * p + j];
            eb->Q[j * p + l] = delta / h;
            scale[2 * p + j] += fabs(delta);
        }
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

/* The Jacobian's put(): K into couplings, P and Q; position rows are left to the kinematics
 * check of the verifying probe. */
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
    else if (col >= 2 * p)
        status = JACOBIAN_QUADRATURE;
    else if (row < 2 * p && col % 2 == 1)
        status = JACOBIAN_VELOCITY;
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
    case JACOBIAN_VELOCITY:
        return refuse_velocity(eb->bad_row / 2, eb->bad_col / 2, err);
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
        const coupling *cp = &eb->couplings[e];
        double change = -cp->value * delta[2 * cp->col];
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
    for (size_t k = 0; k < n; ++k) {
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

static size_t find_set(size_t *parent, size_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Cluster k moves as one: two or more pairs of equal mass, equal starting velocity, equal
 * acceleration and equal rate of it, whose rows of K sum alike (to rounding: the ends of a
 * free chain sum their couplings in another order). */
static int uniform_cluster(const exact_backend *eb, size_t k)
{
    size_t first = eb->first[k], size = eb->first[k + 1] - first;
    if (size < 2)
        return 0;
    size_t a = eb->members[first];
    for (size_t r = 1; r < size; ++r) {
        size_t i = eb->members[first + r];
        if (eb->sqrt_mass[i] != eb->sqrt_mass[a] || eb->y0[2 * i + 1] != eb->y0[2 * a + 1] ||
            eb->accel0[i] != eb->accel0[a] || eb->accel_rate[i] != eb->accel_rate[a])
            return 0;
        double scale = fmax(eb->row_scale[i], eb->row_scale[a]);
        if (fabs(eb->row_sum[i] - eb->row_sum[a]) > 16.0 * DBL_EPSILON * scale)
            return 0;
    }
    return 1;
}

/* Clusters: connected components of K's couplings (a set's root is its smallest pair), in
 * the order of their first pairs; each cluster's S assembled densely. */
static int split_clusters(exact_backend *eb, bk_error *err)
{
    size_t p = eb->p, *parent = eb->parent;
    for (size_t i = 0; i < p; ++i)
        parent[i] = i;
    for (size_t e = 0; e < eb->n_couplings; ++e) {
        size_t a = find_set(parent, eb->couplings[e].row), b = find_set(parent, eb->couplings[e].col);
        if (a < b)
            parent[b] = a;
        else if (b < a)
            parent[a] = b;
    }
    size_t count = 0;
    for (size_t i = 0; i < p; ++i) {
        size_t root = find_set(parent, i);
        if (root == i) {
            eb->cluster_of[i] = count;
            eb->first[count++] = 0;
        } else {
            eb->cluster_of[i] = eb->cluster_of[root];
        }
        eb->first[eb->cluster_of[i]]++;
    }
    eb->n_clusters = count;
    /* Sizes into each cluster's first mode. */
    size_t placed = 0;
    for (size_t k = 0; k < count; ++k) {
        size_t size = eb->first[k];
        eb->first[k] = placed;
        placed += size;
    }
    eb->first[count] = placed;
    for (size_t k = 0; k < count; ++k)
        parent[k] = eb->first[k]; /* the next free member slot */
    for (size_t i = 0; i < p; ++i) {
        size_t k = eb->cluster_of[i];
        eb->local[i] = parent[k] - eb->first[k];
        eb->members[parent[k]++] = i;
    }
    for (size_t i = 0; i < p; ++i)
        eb->row_sum[i] = eb->row_scale[i] = 0.0;
    for (size_t e = 0; e < eb->n_couplings; ++e) {
        const coupling *cp = &eb->couplings[e];
        eb->row_sum[cp->row] += cp->value;
        eb->row_scale[cp->row] = fmax(eb->row_scale[cp->row], fabs(cp->value));
    }
    /* Matrix offsets: a uniform cluster needs none. */
    size_t total = 0, largest = 0;
    for (size_t k = 0; k < count; ++k) {
        size_t size = eb->first[k + 1] - eb->first[k];
        eb->uniform[k] = (size_t)uniform_cluster(eb, k);
        eb->offset[k] = total;
        if (eb->uniform[k])
            continue;
        total += size * size;
        largest = size > largest ? size : largest;
    }
    eb->offset[count] = total;
    int rc = reserve_matrices(eb, total, largest, err);
    if (rc != BK_OK)
        return rc;
    memset(eb->S, 0, total * sizeof *eb->S);
    for (size_t e = 0; e < eb->n_couplings; ++e) {
        const coupling *cp = &eb->couplings[e];
        size_t k = eb->cluster_of[cp->row], size = eb->first[k + 1] - eb->first[k];
        if (!eb->uniform[k])
            eb->S[eb->offset[k] + eb->local[cp->row] * size + eb->local[cp->col]] += cp->value;
    }
    return BK_OK;
}

/* Whether the size x size S has entries only on its three middle diagonals. */
static int tridiagonal(const double *S, size_t size)
{
    for (size_t r = 0; r < size; ++r)
        for (size_t q = 0; q < size; ++q)
            if ((r > q + 1 || q > r + 1) && S[r * size + q] != 0.0)
                return 0;
    return 1;
}

/* Eigenvalues and eigenvectors (columns of U) of the symmetric size x size S (kept intact):
 * LAPACK's dstevr when S is tridiagonal (a stretch of the chain: O(size^2)), else GSL's
 * dense symmv (a ring slipping all round). */
static int eigen_decompose(exact_backend *eb, const double *S, size_t size, double *lambda,
                           double *U, bk_error *err)
{
    size_t count = size * size;
    if (size == 1) {
        lambda[0] = S[0];
        U[0] = 1.0;
        return BK_OK;
    }
    if (tridiagonal(S, size)) {
        /* d and e in the work copy, the support indices after them. */
        double *d = eb->work, *e = eb->work + size;
        for (size_t r = 0; r < size; ++r) {
            d[r] = S[r * size + r];
            if (r + 1 < size)
                e[r] = S[r * size + r + 1];
        }
        lapack_int found = 0, n = (lapack_int)size;
        lapack_int *support = (lapack_int *)(void *)(eb->work + 2 * size);
        lapack_int info = LAPACKE_dstevr(LAPACK_ROW_MAJOR, 'V', 'A', n, d, e, 0.0, 0.0, 0, 0, 0.0,
                                         &found, lambda, U, n, support);
        if (info != 0 || found != n)
            return BK_FAIL(err, BK_ERR_SOLVER,
                           "exact stepper: tridiagonal eigen-decomposition of %zu modes failed "
                           "(LAPACK dstevr info %d, %d found)", size, (int)info, (int)found);
        return BK_OK;
    }
    /* GSL documents the workspace for one matrix size: keep it exactly this one. */
    if (!eb->eigen || eb->eigen->size != size) {
        if (eb->eigen)
            gsl_eigen_symmv_free(eb->eigen);
        eb->eigen = gsl_eigen_symmv_alloc(size);
        if (!eb->eigen)
            return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for %zu modes", size);
    }
    memcpy(eb->work, S, count * sizeof *S);
    gsl_matrix_view A = gsl_matrix_view_array(eb->work, size, size);
    gsl_matrix_view V = gsl_matrix_view_array(U, size, size);
    gsl_vector_view values = gsl_vector_view_array(lambda, size);
    int rc = gsl_eigen_symmv(&A.matrix, &values.vector, &V.matrix, eb->eigen);
    if (rc != GSL_SUCCESS)
        return BK_FAIL(err, BK_ERR_SOLVER, "exact stepper: eigen-decomposition failed: %s",
                       gsl_strerror(rc));
    return BK_OK;
}

/* Cluster k: symmetrise its S, diagonalise; its modes' frequencies, initial velocities and
 * forcing, and T = M^(-1/2) U. */
/* A uniform cluster: one oscillator in the pairs' own units (u = eta for every member), its
 * frequency the rows' common sum; the other modes are idle at that frequency (so that the
 * sampling step stays what the cluster needs). */
static int uniform_modes(exact_backend *eb, size_t k, bk_error *err)
{
    size_t first = eb->first[k], size = eb->first[k + 1] - first;
    const size_t *members = &eb->members[first];
    size_t a = members[0];
    double l = eb->row_sum[a];
    if (l < -ZERO_MODE * eb->row_scale[a])
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact: mode %zu is unstable (negative stiffness eigenvalue %.6g "
                       "s^-2); only oscillating or free modes are solved exactly" USE_INTEGRATOR,
                       first, l);
    if (l <= ZERO_MODE * eb->row_scale[a])
        l = 0.0;
    for (size_t q = 0; q < size; ++q) {
        eb->omega2[first + q] = l;
        eb->omega[first + q] = sqrt(l);
        eb->c[first + q] = q == 0 ? eb->y0[2 * a + 1] : 0.0;
        eb->g[first + q] = q == 0 ? eb->accel0[a] : 0.0;
        eb->d[first + q] = q == 0 ? eb->accel_rate[a] : 0.0;
    }
    for (size_t j = 0; j < eb->m; ++j) {
        const double *Pj = &eb->P[j * eb->p], *Qj = &eb->Q[j * eb->p];
        double pq = 0.0, qq = 0.0;
        for (size_t r = 0; r < size; ++r) {
            pq += Pj[members[r]];
            qq += Qj[members[r]];
        }
        for (size_t q = 0; q < size; ++q) {
            eb->P_modal[j * eb->p + first + q] = q == 0 ? pq : 0.0;
            eb->Q_modal[j * eb->p + first + q] = q == 0 ? qq : 0.0;
        }
    }
    return BK_OK;
}

static int cluster_modes(exact_backend *eb, size_t k, bk_error *err)
{
    if (eb->uniform[k])
        return uniform_modes(eb, k, err);
    size_t first = eb->first[k], size = eb->first[k + 1] - first;
    const size_t *members = &eb->members[first];
    double *S = &eb->S[eb->offset[k]], *T = &eb->T[eb->offset[k]];
    double s_max = 0.0;
    for (size_t r = 0; r < size; ++r)
        for (size_t q = 0; q < size; ++q) {
            S[r * size + q] *= eb->sqrt_mass[members[r]] / eb->sqrt_mass[members[q]];
            s_max = fmax(s_max, fabs(S[r * size + q]));
        }
    for (size_t r = 0; r < size; ++r)
        for (size_t q = r + 1; q < size; ++q) {
            double a = S[r * size + q], b = S[q * size + r];
            if (fabs(a - b) > STRUCTURE_TOL * s_max)
                return BK_FAIL(err, BK_ERR_CONFIG,
                               "method exact: the stiffness coupling pairs %zu and %zu is not "
                               "symmetric with the pair masses (%.6g vs %.6g)" USE_INTEGRATOR,
                               members[r], members[q], a, b);
            S[r * size + q] = S[q * size + r] = 0.5 * (a + b);
        }
    double *omega2 = &eb->omega2[first];
    int rc = eigen_decompose(eb, S, size, omega2, T, err);
    if (rc != BK_OK)
        return rc;
    double lambda_max = 0.0;
    for (size_t q = 0; q < size; ++q)
        lambda_max = fmax(lambda_max, fabs(omega2[q]));
    for (size_t q = 0; q < size; ++q) {
        double l = omega2[q];
        if (l < -ZERO_MODE * lambda_max)
            return BK_FAIL(err, BK_ERR_CONFIG,
                           "method exact: mode %zu is unstable (negative stiffness eigenvalue %.6g "
                           "s^-2); only oscillating or free modes are solved exactly" USE_INTEGRATOR,
                           first + q, l);
        if (l <= ZERO_MODE * lambda_max)
            l = 0.0;
        omega2[q] = l;
        eb->omega[first + q] = sqrt(l);
    }
    for (size_t q = 0; q < size; ++q) {
        double c = 0.0, g = 0.0, d = 0.0;
        for (size_t r = 0; r < size; ++r) {
            size_t i = members[r];
            double u = T[r * size + q] * eb->sqrt_mass[i];
            c += u * eb->y0[2 * i + 1];
            g += u * eb->accel0[i];
            d += u * eb->accel_rate[i];
        }
        eb->c[first + q] = c;
        eb->g[first + q] = g;
        eb->d[first + q] = d;
    }
    for (size_t r = 0; r < size; ++r)
        for (size_t q = 0; q < size; ++q)
            T[r * size + q] /= eb->sqrt_mass[members[r]];
    /* Quadrature coefficients into this cluster's modal coordinates. */
    for (size_t j = 0; j < eb->m; ++j) {
        const double *Pj = &eb->P[j * eb->p], *Qj = &eb->Q[j * eb->p];
        for (size_t q = 0; q < size; ++q) {
            double pq = 0.0, qq = 0.0;
            for (size_t r = 0; r < size; ++r) {
                pq += Pj[members[r]] * T[r * size + q];
                qq += Qj[members[r]] * T[r * size + q];
            }
            eb->P_modal[j * eb->p + first + q] = pq;
            eb->Q_modal[j * eb->p + first + q] = qq;
        }
    }
    return BK_OK;
}

/* Every cluster's modes, and the sampling step. */
static int modes(exact_backend *eb, bk_error *err)
{
    size_t p = eb->p;
    for (size_t i = 0; i < p; ++i) {
        double mass = eb->problem.pair_mass[i];
        if (!(mass > 0.0) || !isfinite(mass))
            return BK_FAIL(err, BK_ERR_INVALID, "exact stepper: pair %zu has mass %g", i, mass);
        eb->sqrt_mass[i] = sqrt(mass);
    }
    int rc = split_clusters(eb, err);
    for (size_t k = 0; k < eb->n_clusters && rc == BK_OK; ++k)
        rc = cluster_modes(eb, k, err);
    if (rc != BK_OK)
        return rc;
    double lambda_max = 0.0;
    for (size_t k = 0; k < p; ++k)
        lambda_max = fmax(lambda_max, eb->omega2[k]);
    /* Sampling step: a sixteenth of the shortest period, max_step, else a sixteenth of the
     * span (polynomial motion only). */
    double h = lambda_max > 0.0 ? 2.0 * PI / (SAMPLES_PER_PERIOD * sqrt(lambda_max)) : INFINITY;
    double max_step = eb->options.max_step;
    if (isfinite(max_step) && max_step > 0.0 && max_step < h)
        h = max_step;
    if (!isfinite(h)) {
        double span = eb->t_stop - eb->t0;
        h = isfinite(span) && span > 0.0 ? span / SAMPLES_PER_PERIOD : 1.0 + fabs(eb->t0);
    }
    eb->h = h;
    return BK_OK;
}

static int start(void *mem, const bk_ode_problem *problem, double t0, const double *y0,
                 const double *atol, size_t n, double t_stop, bk_error *err)
{
    (void)atol; /* exact: no tolerance to meet */
    exact_backend *eb = mem;
    eb->problem = *problem;
    if (!problem->affine)
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact needs Coulomb friction (constant sliding force, no friction "
                       "state)" USE_INTEGRATOR);
    size_t p = problem->n_pairs;
    if (2 * p > n || (p > 0 && !problem->pair_mass))
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact needs the state as (position, velocity) pairs followed only "
                       "by quadratures (n = %zu, n_pairs = %zu)" USE_INTEGRATOR,
                       n, p);
    if (!isfinite(t0) || !(t_stop >= t0))
        return BK_FAIL(err, BK_ERR_INVALID, "exact stepper: bad interval [%.17g, %.17g] s", t0, t_stop);
    int rc = reserve(eb, n, p, n - 2 * p, problem->n_roots, err);
    if (rc != BK_OK)
        return rc;
    eb->n = n;
    eb->p = p;
    eb->m = n - 2 * p;
    eb->n_roots = problem->n_roots;
    eb->t0 = eb->t_now = eb->t_lo = eb->t_hi = t0;
    eb->t_stop = t_stop;
    eb->g_try_time = NAN;
    eb->n_couplings = 0;
    eb->n_clusters = 0;
    memcpy(eb->y0, y0, n * sizeof *y0);
    memset(eb->P, 0, eb->m * p * sizeof *eb->P);
    memset(eb->Q, 0, eb->m * p * sizeof *eb->Q);

    if ((rc = probe_forcing(eb, err)) != BK_OK ||
        (rc = problem->jacobian ? read_jacobian(eb, err) : probe_columns(eb, err)) != BK_OK ||
        (rc = modes(eb, err)) != BK_OK)
        return rc;

    if (eb->n_roots > 0) {
        memcpy(eb->direction, problem->root_direction, eb->n_roots * sizeof *eb->direction);
        if ((rc = call_roots(eb, t0, eb->g_hi, err)) != BK_OK)
            return rc;
        for (size_t i = 0; i < eb->n_roots; ++i)
            eb->sign[i] = (signed char)(eb->g_hi[i] > 0.0 ? 1 : eb->g_hi[i] < 0.0 ? -1 : 0);
    }
    return BK_OK;
}

/* --- step: sample, bracket, locate ------------------------------------------------------ */

/* Has function i crossed, in a direction it listens to, from its last sign to value g? */
static int crossed(const exact_backend *eb, size_t i, double g)
{
    int s = eb->sign[i];
    if (s == 0 || g * s > 0.0)
        return 0;
    return eb->direction[i] == 0 || eb->direction[i] == -s;
}

/* All root functions at t into g_try, unless they are there already. */
static int roots_at(exact_backend *eb, double t, bk_error *err)
{
    if (eb->g_try_time == t)
        return BK_OK;
    eb->g_try_time = NAN;
    int rc = call_roots(eb, t, eb->g_try, err);
    if (rc == BK_OK)
        eb->g_try_time = t;
    return rc;
}

/* Every probe evaluates all root functions on the whole state, so a locate remembers the
 * values of its function it has seen: Brent asks again for the bracket's ends. */
#define ROOT_MEMO 8

typedef struct root_probe {
    exact_backend *eb;
    size_t index;
    bk_error *err;
    int status;
    size_t seen;                /* values remembered, the last ROOT_MEMO of them in the ring */
    double seen_t[ROOT_MEMO], seen_g[ROOT_MEMO];
} root_probe;

static void remember(root_probe *rp, double t, double g)
{
    rp->seen_t[rp->seen % ROOT_MEMO] = t;
    rp->seen_g[rp->seen % ROOT_MEMO] = g;
    rp->seen++;
}

static double root_value(double t, void *user)
{
    root_probe *rp = user;
    if (rp->status != BK_OK)
        return NAN;
    size_t known = rp->seen < ROOT_MEMO ? rp->seen : ROOT_MEMO;
    // cppcheck-suppress knownConditionTrueFalse ; seen grows through fn.params across calls
    for (size_t k = 0; k < known; ++k)
        if (rp->seen_t[k] == t)
            return rp->seen_g[k];
    rp->status = roots_at(rp->eb, t, rp->err);
    if (rp->status != BK_OK)
        return NAN;
    double g = rp->eb->g_try[rp->index];
    remember(rp, t, g);
    return g;
}

/* Locate the crossing of function i in [lo, hi] (its old sign at or before lo, its new sign
 * or zero at hi, value g_hi): *t_root is the earliest time found where it holds its new
 * sign or zero, within a few doubles of the zero. */
static int locate(exact_backend *eb, size_t i, double lo, double hi, double g_hi, double *t_root,
                  bk_error *err)
{
    root_probe rp = {.eb = eb, .index = i, .err = err, .status = BK_OK};
    gsl_function fn = {root_value, &rp};
    int old = eb->sign[i];
    if (g_hi == 0.0 || hi <= lo) {
        *t_root = hi;
        return BK_OK;
    }
    remember(&rp, hi, g_hi);
    /* lo's value differs from the last sign seen only when it is exactly zero there: the
     * crossing is at lo. */
    double g_lo = root_value(lo, &rp);
    if (rp.status != BK_OK)
        return rp.status;
    if (g_lo * old <= 0.0) {
        *t_root = lo;
        return BK_OK;
    }
    for (int attempt = 0; attempt < 64; ++attempt) {
        if (g_hi == 0.0 || hi <= lo) {
            *t_root = hi;
            return BK_OK;
        }
        int rc = gsl_root_fsolver_set(eb->brent, &fn, lo, hi);
        if (rp.status != BK_OK)
            return rp.status;
        if (rc != GSL_SUCCESS)
            return BK_FAIL(err, BK_ERR_SOLVER,
                           "exact stepper: cannot bracket root function %zu in [%.17g, %.17g] s: %s",
                           i, lo, hi, gsl_strerror(rc));
        double a = lo, b = hi;
        for (int iter = 0; iter < BRENT_MAX_ITER; ++iter) {
            rc = gsl_root_fsolver_iterate(eb->brent);
            // cppcheck-suppress knownConditionTrueFalse ; set through fn.params by the callback
            if (rp.status != BK_OK)
                return rp.status;
            if (rc != GSL_SUCCESS)
                return BK_FAIL(err, BK_ERR_SOLVER,
                               "exact stepper: locating root function %zu failed: %s", i,
                               gsl_strerror(rc));
            a = gsl_root_fsolver_x_lower(eb->brent);
            b = gsl_root_fsolver_x_upper(eb->brent);
            if (b - a <= 2.0 * DBL_EPSILON * fmax(fabs(a), fabs(b)))
                break;
        }
        double g_b = root_value(b, &rp);
        if (rp.status != BK_OK)
            return rp.status;
        if (g_b * old <= 0.0) {
            *t_root = b;
            return BK_OK;
        }
        /* Brent closed on a later crossing back: an earlier one lies in [lo, a]. */
        hi = a;
        g_hi = root_value(a, &rp);
        if (rp.status != BK_OK)
            return rp.status;
    }
    return BK_FAIL(err, BK_ERR_SOLVER, "exact stepper: root function %zu oscillates too fast to locate "
                   "near t = %.17g s", i, lo);
}

static void update_signs(exact_backend *eb, const double *g)
{
    for (size_t i = 0; i < eb->n_roots; ++i)
        if (g[i] != 0.0)
            eb->sign[i] = (signed char)(g[i] > 0.0 ? 1 : -1);
}

static size_t count_crossed(const exact_backend *eb, const double *g)
{
    size_t count = 0;
    for (size_t i = 0; i < eb->n_roots; ++i)
        count += (size_t)crossed(eb, i, g[i]);
    return count;
}

/* On a long chain many functions cross within one sampling step, and locating each to the
 * last double (a few dozen probes) only to report the first made the cost per transition
 * grow with the chain.  Halve (lo, hi] (values g_hi at hi) toward the earliest crossing
 * until one function crosses in it, each halving one probe; crossings closer than
 * h / 2^MAX_HALVINGS (simultaneous ones) are left to find_roots. */
static int isolate_first(exact_backend *eb, double *lo, double *hi, bk_error *err)
{
    size_t crossing = count_crossed(eb, eb->g_hi);
    for (int halving = 0; halving < MAX_HALVINGS && crossing > 1; ++halving) {
        double mid = *lo + 0.5 * (*hi - *lo);
        int rc = roots_at(eb, mid, err);
        if (rc != BK_OK)
            return rc;
        size_t early = count_crossed(eb, eb->g_try);
        if (early > 0) {
            *hi = mid;
            memcpy(eb->g_hi, eb->g_try, eb->n_roots * sizeof *eb->g_hi);
            crossing = early;
        } else {
            /* Nothing listened to crossed by mid: the signs there are the new reference. */
            update_signs(eb, eb->g_try);
            *lo = mid;
            crossing = count_crossed(eb, eb->g_hi);
        }
    }
    return BK_OK;
}

/* Look for crossings in (lo, hi] (values g at hi).  Returns 1 with *t_root and found[] when
 * some function crossed, 0 when none did, < 0 on failure.  Everything crossing within the
 * root tolerance of the first crossing is one event, reported at the latest of their
 * located times so that each has crossed there.  Only one function is located per round:
 * the rest are sorted by evaluating all of them just before and just after its root, so a
 * uniform stretch of p blocks stopping together costs one location, not p (each a few
 * dozen probes of all p functions). */
static int find_roots(exact_backend *eb, double lo, double hi, double *t_root, bk_error *err)
{
    size_t nr = eb->n_roots;
    double *g = eb->g_hi;
    for (size_t round = 0; round < nr + 64; ++round) {
        size_t pick = nr;
        for (size_t i = 0; i < nr && pick == nr; ++i)
            if (crossed(eb, i, g[i]))
                pick = i;
        if (pick == nr)
            return 0;
        double first;
        int rc = locate(eb, pick, lo, hi, g[pick], &first, err);
        if (rc != BK_OK)
            return rc;
        double tol = 100.0 * DBL_EPSILON * (fabs(first) + eb->h);
        /* Another function crossed before this one's window: that crossing comes first. */
        double before = first - tol;
        if (before > lo) {
            if ((rc = roots_at(eb, before, err)) != BK_OK)
                return rc;
            if (count_crossed(eb, eb->g_try) > 0) {
                hi = before;
                memcpy(g, eb->g_try, nr * sizeof *g);
                continue;
            }
        }
        /* Functions crossing just after it belong to the same event: locate those. */
        double t = first, after = fmin(first + tol, hi);
        if (after > first) {
            if ((rc = roots_at(eb, after, err)) != BK_OK)
                return rc;
            memcpy(eb->root_t, eb->g_try, nr * sizeof *eb->root_t); /* values at after */
            if ((rc = roots_at(eb, first, err)) != BK_OK)
                return rc;
            for (size_t i = 0; i < nr; ++i) {
                if (!crossed(eb, i, eb->root_t[i]) || crossed(eb, i, eb->g_try[i]))
                    continue;
                double t_i;
                if ((rc = locate(eb, i, first, after, eb->root_t[i], &t_i, err)) != BK_OK)
                    return rc;
                t = fmax(t, t_i);
                /* locate probed elsewhere: the values at first are wanted again below. */
                if ((rc = roots_at(eb, first, err)) != BK_OK)
                    return rc;
            }
        }
        if ((rc = roots_at(eb, t, err)) != BK_OK)
            return rc;
        for (size_t i = 0; i < nr; ++i)
            eb->found[i] = crossed(eb, i, eb->g_try[i]) ? -eb->sign[i] : 0;
        eb->found[pick] = -eb->sign[pick];
        update_signs(eb, eb->g_try);
        for (size_t i = 0; i < nr; ++i)
            if (eb->found[i])
                eb->sign[i] = (signed char)eb->found[i];
        *t_root = t;
        return 1;
    }
    return BK_FAIL(err, BK_ERR_SOLVER, "exact stepper: cannot separate the roots near t = %.17g s", lo);
}

static int step(void *mem, double *t_reached, double *y, bk_error *err)
{
    exact_backend *eb = mem;
    double lo = eb->t_now;
    if (lo >= eb->t_stop) {
        eb->t_lo = eb->t_hi = eb->t_stop;
        exact_state(eb, eb->t_stop, y);
        *t_reached = eb->t_stop;
        return BK_STEP_STOP;
    }
    double hi = lo + eb->h;
    /* Never leave a sliver before the stop time. */
    if (!(hi < eb->t_stop - 1e-3 * eb->h))
        hi = eb->t_stop;
    eb->counters.steps++;
    int rc = call_roots(eb, hi, eb->g_hi, err);
    if (rc != BK_OK)
        return rc;
    double from = lo;
    if (eb->n_roots > 0 && (rc = isolate_first(eb, &from, &hi, err)) != BK_OK)
        return rc;
    double t_root = hi;
    int status = eb->n_roots > 0 ? find_roots(eb, from, hi, &t_root, err) : 0;
    if (status < 0)
        return status;
    eb->t_lo = lo;
    if (status == 1) {
        eb->t_now = eb->t_hi = t_root;
        exact_state(eb, t_root, y);
        *t_reached = t_root;
        return BK_STEP_ROOT;
    }
    update_signs(eb, eb->g_hi);
    eb->t_now = eb->t_hi = hi;
    exact_state(eb, hi, y);
    *t_reached = hi;
    return hi == eb->t_stop ? BK_STEP_STOP : BK_STEP_OK;
}

static int interpolate(void *mem, double t, double *y, bk_error *err)
{
    exact_backend *eb = mem;
    if (!(t >= eb->t0 && t <= eb->t_stop))
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "exact stepper: t = %.17g s is outside the solution [%.17g, %.17g] s", t,
                       eb->t0, eb->t_stop);
    exact_state(eb, t, y);
    return BK_OK;
}

static void last_step(void *mem, double *t_lo, double *t_hi)
{
    exact_backend *eb = mem;
    *t_lo = eb->t_lo;
    *t_hi = eb->t_hi;
}

static int root_info(void *mem, int *found)
{
    exact_backend *eb = mem;
    if (eb->n_roots > 0)
        memcpy(found, eb->found, eb->n_roots * sizeof *found);
    return BK_OK;
}

static void counters(void *mem, bk_solver_counters *c)
{
    exact_backend *eb = mem;
    *c = eb->counters;
}

const bk_solver_backend bk_solver_exact = {
    .name = "exact",
    .doc = "exact piecewise-analytic (modal) stepper for Coulomb friction; roots to ~1e-15",
    .create = create,
    .start = start,
    .step = step,
    .interpolate = interpolate,
    .last_step = last_step,
    .root_info = root_info,
    .counters = counters,
    .destroy = destroy,
};
