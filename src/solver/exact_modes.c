/* The exact stepper's modes: the clusters (connected components of K's coupling), each
 * symmetrised and diagonalised (LAPACK dstevr for a free-ended stretch, GSL symmv for a
 * cyclic one, one oscillator for a uniform one), and the closed-form state from them.
 * Why each choice: exact.c's header. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>
#include <lapacke.h>

#include "exact_backend.h"

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

/* Every mode's eta, eta' - c and their integrals at tau = t - t0: O(p).  A damped mode's
 * forcing at the start is g + gamma c (g is its acceleration there, which the dashpot's
 * -gamma c already holds); eta' - c and its integral keep the undamped forms (exact.c's
 * header). */
void bk_exact_modal_amplitudes(exact_backend *eb, double tau)
{
    for (size_t k = 0; k < eb->p; ++k) {
        double ck = eb->c[k], gk = eb->g[k], dk = eb->d[k];
        if (ck == 0.0 && gk == 0.0 && dk == 0.0) { /* idle (all but one mode of a uniform cluster) */
            eb->eta[k] = eb->deta[k] = eb->ieta[k] = eb->idv[k] = 0.0;
            continue;
        }
        double phi[5], w2 = eb->omega2[k], gamma = eb->gamma[k];
        if (gamma == 0.0)
            basis(eb->omega[k], tau, phi);
        else
            bk_exact_damped_basis(w2, gamma, eb->root[k], eb->radius[k], tau, phi);
        double forcing = gk + gamma * ck;
        eb->eta[k] = ck * phi[1] + forcing * phi[2] + dk * phi[3];
        eb->deta[k] = -w2 * ck * phi[2] + gk * phi[1] + dk * phi[2];
        eb->ieta[k] = ck * phi[2] + forcing * phi[3] + dk * phi[4];
        eb->idv[k] = (dk - w2 * ck) * phi[3] + gk * phi[2];
    }
    if (eb->n_coupled > 0)
        bk_exact_coupled_amplitudes(eb, tau);
}

/* Cluster cl's pairs from the amplitudes: O(size) for a uniform cluster, else O(size^2)
 * (4 size^2 for a coupled one). */
void bk_exact_cluster_state(const exact_backend *eb, size_t cl, double *y)
{
    size_t first = eb->first[cl], size = eb->first[cl + 1] - first;
    const double *T = &eb->T[eb->offset[cl]];
    const double *eta = &eb->eta[first], *deta = &eb->deta[first];
    if (eb->coupled[cl]) {
        bk_exact_coupled_state(eb, cl, y);
        return;
    }
    if (eb->uniform[cl]) {
        for (size_t r = 0; r < size; ++r) {
            size_t i = eb->members[first + r];
            y[2 * i] = eb->y0[2 * i] + eta[0];
            y[2 * i + 1] = eb->y0[2 * i + 1] + deta[0];
        }
        return;
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

/* The dashpots' dissipation from each damped mode's energy balance: multiplying
 * eta'' + gamma eta' + w^2 eta = f(tau) by eta' and integrating,
 *     gamma int eta'^2 = -(eta'^2 - c^2) / 2 - w^2 eta^2 / 2 + int f eta'
 *                      = -deta (2 c + deta) / 2 - w^2 eta^2 / 2 + f0 eta + d (tau eta - ieta),
 * f0 = g + gamma c, and the cluster's v^T C v is the sum of gamma_k eta_k'^2 (C is diagonal
 * in the modes), weighted by the mode's mass (1 in mass-normalised coordinates).  No
 * quadrature of its own is needed, and it is exact like the rest: O(p). */
static double dissipation(const exact_backend *eb, double tau)
{
    double sum = 0.0;
    for (size_t k = 0; k < eb->p; ++k) {
        if (eb->gamma[k] == 0.0)
            continue;
        double ck = eb->c[k], eta = eb->eta[k], deta = eb->deta[k];
        double forcing = eb->g[k] + eb->gamma[k] * ck;
        double balance = -0.5 * deta * (2.0 * ck + deta) - 0.5 * eb->omega2[k] * eta * eta +
                         forcing * eta + eb->d[k] * (tau * eta - eb->ieta[k]);
        sum += eb->mode_mass[k] * balance;
    }
    return sum;
}

/* The quadratures from the amplitudes: O(m p). */
void bk_exact_quadratures(const exact_backend *eb, double tau, double *y)
{
    size_t p = eb->p, affine_m = eb->m - (size_t)eb->dissipation;
    for (size_t j = 0; j < affine_m; ++j) {
        const double *Pj = &eb->P_modal[j * p], *Qj = &eb->Q_modal[j * p];
        double sum = 0.0;
        for (size_t k = 0; k < p; ++k)
            sum += Pj[k] * eb->ieta[k] + Qj[k] * eb->idv[k];
        if (eb->n_coupled > 0)
            sum += bk_exact_coupled_quadrature(eb, j);
        y[2 * p + j] = eb->y0[2 * p + j] + (eb->qdot0[j] + 0.5 * eb->q_rate[j] * tau) * tau + sum;
    }
    if (eb->dissipation)
        y[eb->n - 1] = eb->y0[eb->n - 1] + dissipation(eb, tau) +
                       (eb->n_coupled > 0 ? bk_exact_coupled_dissipation(eb, tau) : 0.0);
}

/* The exact state at time t into y (size n): O(p) modes, O(sum p_i^2) back to the pairs. */
void bk_exact_state(exact_backend *eb, double t, double *y)
{
    double tau = t - eb->t0;
    bk_exact_modal_amplitudes(eb, tau);
    for (size_t cl = 0; cl < eb->n_clusters; ++cl)
        bk_exact_cluster_state(eb, cl, y);
    bk_exact_quadratures(eb, tau, y);
}

static int reserve_matrices(exact_backend *eb, size_t total, size_t largest, bk_error *err)
{
    size_t need = 2 * total + 1;
    double *matrices = bk_fit_buffer(eb->matrices, &eb->matrices_cap, need, sizeof *matrices);
    if (!matrices)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the modes of %zu pairs",
                       eb->p);
    eb->matrices = matrices;
    eb->S = eb->matrices;
    eb->T = eb->S + total;
    return bk_exact_reserve_work(eb, largest, err);
}

static int descending(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x < y) - (x > y);
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
 * acceleration and equal rate of it, whose rows of K sum alike and rows of D too (to
 * rounding: the ends of a free chain sum their couplings in another order). */
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
        /* the dashpots too: the same damping force on every member moving alike */
        double damp_scale = fmax(eb->damp_scale[i], eb->damp_scale[a]);
        if (fabs(eb->damp_sum[i] - eb->damp_sum[a]) > 16.0 * DBL_EPSILON * damp_scale)
            return 0;
    }
    return 1;
}

static void join(size_t *parent, const coupling *cp)
{
    size_t a = find_set(parent, cp->row), b = find_set(parent, cp->col);
    if (a < b)
        parent[b] = a;
    else if (b < a)
        parent[a] = b;
}

/* Clusters: connected components of K's and D's couplings (a set's root is its smallest
 * pair), in the order of their first pairs; each cluster's S assembled densely. */
static int split_clusters(exact_backend *eb, bk_error *err)
{
    size_t p = eb->p, *parent = eb->parent;
    for (size_t i = 0; i < p; ++i)
        parent[i] = i;
    for (size_t e = 0; e < eb->n_couplings; ++e)
        join(parent, &eb->shared->couplings[e]);
    for (size_t e = 0; e < eb->n_dampings; ++e)
        join(parent, &eb->shared->dampings[e]);
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
        const coupling *cp = &eb->shared->couplings[e];
        eb->row_sum[cp->row] += cp->value;
        eb->row_scale[cp->row] = fmax(eb->row_scale[cp->row], fabs(cp->value));
    }
    for (size_t i = 0; i < p; ++i)
        eb->damp_sum[i] = eb->damp_scale[i] = 0.0;
    for (size_t e = 0; e < eb->n_dampings; ++e) {
        const coupling *cp = &eb->shared->dampings[e];
        eb->damp_sum[cp->row] += cp->value;
        eb->damp_scale[cp->row] = fmax(eb->damp_scale[cp->row], fabs(cp->value));
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
    memset(eb->S, 0, 2 * total * sizeof *eb->S);
    for (size_t e = 0; e < eb->n_couplings; ++e) {
        const coupling *cp = &eb->shared->couplings[e];
        size_t k = eb->cluster_of[cp->row], size = eb->first[k + 1] - eb->first[k];
        if (!eb->uniform[k])
            eb->S[eb->offset[k] + eb->local[cp->row] * size + eb->local[cp->col]] += cp->value;
    }
    /* D symmetrised, M^(1/2) D M^(-1/2), into T for proportional_damping */
    for (size_t e = 0; e < eb->n_dampings; ++e) {
        const coupling *cp = &eb->shared->dampings[e];
        size_t k = eb->cluster_of[cp->row], size = eb->first[k + 1] - eb->first[k];
        if (!eb->uniform[k])
            eb->T[eb->offset[k] + eb->local[cp->row] * size + eb->local[cp->col]] +=
                cp->value * eb->sqrt_mass[cp->row] / eb->sqrt_mass[cp->col];
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
    double gamma = eb->damp_sum[a], mass = 0.0;
    if (gamma < -ZERO_MODE * eb->damp_scale[a])
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact: mode %zu has negative damping (%.6g s^-1)" USE_INTEGRATOR, first,
                       gamma);
    if (gamma <= ZERO_MODE * eb->damp_scale[a])
        gamma = 0.0;
    for (size_t r = 0; r < size; ++r)
        mass += eb->problem.pair_mass[members[r]];
    for (size_t q = 0; q < size; ++q) {
        eb->omega2[first + q] = l;
        eb->omega[first + q] = sqrt(l);
        eb->gamma[first + q] = gamma;
        eb->mode_mass[first + q] = mass;
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

/* Whether cluster k's damping in the symmetrised coordinates, Cs = M^(1/2) D M^(-1/2)
 * (assembled in its T by split_clusters; the eigenvectors overwrite it after), is
 * alpha I + beta S (S symmetrised already, largest entry s_max): then U diagonalises both and
 * each mode is one damped oscillator, gamma_k = alpha + beta w_k^2.  That is the case of
 * uniform masses with uniform dashpots to the substrate, and of coupling dashpots in the
 * ratio of the coupling springs (C = alpha M + beta K_springs) with uniform driver springs.
 * Other damping couples the modes (their motion is not a sum of real damped oscillators):
 * 0, and exact_coupled.c solves the cluster in its state space. */
static int proportional_damping(const exact_backend *eb, size_t k, double s_max, double *alpha, double *beta)
{
    size_t first = eb->first[k], size = eb->first[k + 1] - first;
    const double *S = &eb->S[eb->offset[k]];
    double *Cs = &eb->T[eb->offset[k]];
    *alpha = *beta = 0.0;
    double c_max = 0.0;
    size_t r_big = 0, q_big = 0;
    double s_off = 0.0;
    for (size_t r = 0; r < size; ++r)
        for (size_t q = 0; q < size; ++q) {
            c_max = fmax(c_max, fabs(Cs[r * size + q]));
            if (r != q && fabs(S[r * size + q]) > s_off) {
                s_off = fabs(S[r * size + q]);
                r_big = r;
                q_big = q;
            }
        }
    /* beta from the largest coupling, alpha from the diagonal's mean */
    if (c_max == 0.0)
        return 1;
    if (s_off > 0.0)
        *beta = 0.5 * (Cs[r_big * size + q_big] + Cs[q_big * size + r_big]) / S[r_big * size + q_big];
    double mean = 0.0;
    for (size_t r = 0; r < size; ++r)
        mean += Cs[r * size + r] - *beta * S[r * size + r];
    *alpha = mean / (double)size;
    double tol = PROPORTIONAL_TOL * (c_max + fabs(*beta) * s_max);
    for (size_t r = 0; r < size; ++r)
        for (size_t q = 0; q < size; ++q) {
            double fit = (r == q ? *alpha : 0.0) + *beta * S[r * size + q];
            if (fabs(Cs[r * size + q] - fit) > tol)
                return 0;
        }
    return 1;
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
    double alpha, beta;
    if (!proportional_damping(eb, k, s_max, &alpha, &beta)) {
        /* exact_coupled.c takes it once every other cluster is done; its mode slots idle */
        eb->coupled[k] = 1;
        eb->n_coupled++;
        for (size_t q = first; q < first + size; ++q) {
            eb->omega2[q] = eb->omega[q] = eb->gamma[q] = 0.0;
            eb->c[q] = eb->g[q] = eb->d[q] = eb->mode_mass[q] = 0.0;
            for (size_t j = 0; j < eb->m; ++j)
                eb->P_modal[j * eb->p + q] = eb->Q_modal[j * eb->p + q] = 0.0;
        }
        return BK_OK;
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
        /* the scale alpha + beta lambda_max stands for: a mode whose damping is below its
         * rounding is undamped, and one clearly negative is refused */
        double gamma = alpha + beta * l, scale = fabs(alpha) + fabs(beta) * lambda_max;
        if (gamma < -PROPORTIONAL_TOL * scale)
            return BK_FAIL(err, BK_ERR_CONFIG,
                           "method exact: mode %zu has negative damping (%.6g s^-1)" USE_INTEGRATOR,
                           first + q, gamma);
        eb->gamma[first + q] = gamma <= PROPORTIONAL_TOL * scale ? 0.0 : gamma;
        eb->mode_mass[first + q] = 1.0;
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
int bk_exact_modes(exact_backend *eb, bk_error *err)
{
    size_t p = eb->p;
    for (size_t i = 0; i < p; ++i) {
        double mass = eb->problem.pair_mass[i];
        if (!(mass > 0.0) || !isfinite(mass))
            return BK_FAIL(err, BK_ERR_INVALID, "exact stepper: pair %zu has mass %g", i, mass);
        eb->sqrt_mass[i] = sqrt(mass);
    }
    eb->n_coupled = 0;
    int rc = split_clusters(eb, err);
    for (size_t k = 0; k < eb->n_clusters && rc == BK_OK; ++k) {
        eb->coupled[k] = 0;
        rc = cluster_modes(eb, k, err);
    }
    if (rc != BK_OK)
        return rc;
    /* Sampling: a sixteenth of 2 pi over the fastest rate any mode varies at (exact.c's
     * header): an oscillating mode's |root| = w, an overdamped one's slow root while its fast
     * one, kept apart (descending), counts only until it decayed. */
    double rate_max = 0.0;
    eb->n_fast = eb->fast_live = 0;
    for (size_t k = 0; k < p; ++k) {
        if (eb->gamma[k] == 0.0) {
            eb->root[k] = eb->radius[k] = eb->omega[k];
            rate_max = fmax(rate_max, eb->omega[k]);
            continue;
        }
        bk_exact_damped_root(eb->omega2[k], eb->gamma[k], &eb->root[k], &eb->radius[k]);
        if (eb->root[k] < 0.0) {
            double sigma = 0.5 * eb->gamma[k], mu = -eb->root[k];
            rate_max = fmax(rate_max, eb->omega2[k] / (sigma + mu));
            eb->fast[eb->n_fast++] = eb->radius[k];
        } else {
            rate_max = fmax(rate_max, eb->radius[k]);
        }
    }
    if (eb->n_coupled > 0 && (rc = bk_exact_coupled_modes(eb, &rate_max, err)) != BK_OK)
        return rc;
    qsort(eb->fast, eb->n_fast, sizeof *eb->fast, descending);
    double h = rate_max > 0.0 ? 2.0 * PI / (SAMPLES_PER_PERIOD * rate_max) : INFINITY;
    double max_step = eb->max_step;
    if (isfinite(max_step) && max_step > 0.0 && max_step < h)
        h = max_step;
    if (!isfinite(h)) {
        /* polynomial motion only, or decay alone: a sixteenth of the span */
        double span = eb->t_stop - eb->t0;
        h = isfinite(span) && span > 0.0 ? span / SAMPLES_PER_PERIOD : 1.0 + fabs(eb->t0);
    }
    eb->h_slow = h;
    eb->h = bk_exact_sampling_step(eb, eb->t0);
    return BK_OK;
}

/* The step from t: h_slow, or a sixteenth of 2 pi over the fastest overdamped decay rate l
 * whose exponential has not yet fallen below e^-FAST_DECAYED (l (t - t0) < FAST_DECAYED).
 * Within such a step e^(-l tau) changes by a factor e^(-2 pi / 16) = 0.68 at most, as an
 * oscillation turns by 22.5 degrees, so a root function, a sum of such exponentials,
 * oscillations and a polynomial, cannot cross and cross back unseen any more than an
 * undamped one can; once the exponential decayed it cannot move a root function at all. */
double bk_exact_sampling_step(exact_backend *eb, double t)
{
    double tau = t - eb->t0;
    while (eb->fast_live < eb->n_fast && eb->fast[eb->fast_live] * tau >= FAST_DECAYED)
        eb->fast_live++;
    if (eb->fast_live == eb->n_fast)
        return eb->h_slow;
    return fmin(eb->h_slow, 2.0 * PI / (SAMPLES_PER_PERIOD * eb->fast[eb->fast_live]));
}
