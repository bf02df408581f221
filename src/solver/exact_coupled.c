/* The exact stepper's clusters whose damping couples their modes (M^(1/2) D M^(-1/2) is not
 * alpha I + beta S: masses, dashpots or driver springs that differ along a slipping stretch).
 * No real basis diagonalises both S and the damping, so the cluster is solved in its state
 * space, z = (q, r) = M^(1/2) (u, v):
 *
 *     z' = A z + (0, M^(1/2) (b0 + b1 tau)),   A = [0 I; -S -Cs],   Cs = M^(1/2) D M^(-1/2),
 *
 * A = V diag(l) V^-1 (LAPACK dgeev, on the positions scaled by the cluster's largest
 * frequency; l real, or pairs l, conj(l) with eigenvectors Re v +- i Im v in two real
 * columns of V).  In the real coordinates xi = V^-1 z every real l is one
 * first-order mode, and a pair (x, y) on columns Re v, Im v is the complex w = x - i y with
 * w' = l w + f_x - i f_y.  From the start,
 *
 *     xi(tau) - xi(0) = G tau phi1(l tau) + F tau^2 phi2(l tau),   G = V^-1 z'(0),
 *                                                                  F = V^-1 (0, M^(1/2) b1),
 *
 * with the exponential integrators' phi_k (exact_damped.c, complex for a pair), and its
 * integral G tau^2 phi2 + F tau^3 phi3: u = M^(-1/2) V_top (xi - xi(0)), v - v0 = M^(-1/2)
 * V_bottom (xi - xi(0)) (V_top xi(0) = q(0) = 0), exact up to rounding times V's condition
 * number, which is checked (COUPLED_MAX_CONDITION: it diverges where two modes merge, at
 * critical damping of one or for an undamped free mode, and such a cluster is refused).  The
 * dashpots' dissipation comes from the cluster's energy balance,
 *
 *     int v^T C v = -(v^T M v - v0^T M v0) / 2 - u^T M K u / 2 + int v^T M (b0 + b1 tau),
 *
 * with int v^T M b = sum m_i (b0_i u_i + b1_i (tau u_i - int u_i)).  A probe costs 4 p^2
 * products per such cluster (2 p^2 for a proportional one), a start one 2p x 2p eigenproblem,
 * O(p^3). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <lapacke.h>

#include "exact_backend.h"

/* Per coupled cluster of size s (N = 2 s modes), at 1 + coupled[k] - 1 in coupled_data. */
typedef struct layout {
    size_t s, N;
    double *re, *im;        /* N: the eigenvalues */
    double *G, *F;          /* N: the modes' rate at the start and forcing rate, real coordinates */
    double *Tq, *Tr;        /* s x N: M^(-1/2) V_top, M^(-1/2) V_bottom */
    double *Pq, *Qr;        /* m x N: the quadratures' P times Tq, Q times Tr */
    double *dxi, *ixi;      /* N: xi - xi(0) and its integral at the last amplitudes' tau */
    double *b0;             /* s: the members' affine forcing at the start (accel0 + D v0) */
    double *q;              /* s: the dissipation's work space, M^(1/2) u */
} layout;

static size_t layout_size(size_t s, size_t m)
{
    size_t N = 2 * s;
    return 8 * N + 2 * s * N + 2 * m * N + 2 * s;
}

static layout layout_at(const exact_backend *eb, size_t cl)
{
    size_t s = eb->first[cl + 1] - eb->first[cl], N = 2 * s;
    double *a = eb->coupled_data + (eb->coupled[cl] - 1);
    layout L = {.s = s, .N = N};
    L.re = a, a += N;
    L.im = a, a += N;
    L.G = a, a += N;
    L.F = a, a += N;
    L.Tq = a, a += s * N;
    L.Tr = a, a += s * N;
    L.Pq = a, a += eb->m * N;
    L.Qr = a, a += eb->m * N;
    L.dxi = a, a += N;
    L.ixi = a, a += N;
    L.b0 = a, a += s;
    L.q = a;
    return L;
}

/* Cluster k's state-space modes into L, with work space work (3 N^2 + 3 N doubles, N = 2 s);
 * *rate_max grows to its pairs' |l|, and its real modes join the fast list. */
static int coupled_cluster(exact_backend *eb, size_t k, const layout *L, double *work, double *rate_max,
                           bk_error *err)
{
    size_t s = L->s, N = L->N, first = eb->first[k];
    const size_t *members = &eb->members[first];
    const double *S = &eb->S[eb->offset[k]], *Cs = &eb->T[eb->offset[k]];
    double *A = work, *V = A + N * N, *LU = V + N * N, *rhs = LU + N * N;
    lapack_int *pivot = (lapack_int *)(void *)(rhs + 2 * N);
    /* In (w q, r), w^2 the largest diagonal of S, positions and velocities weigh alike in
     * the eigenvectors: unscaled, |l| ~ w made them lopsided. */
    double w2 = 0.0;
    for (size_t r = 0; r < s; ++r)
        w2 = fmax(w2, S[r * s + r]);
    double w = w2 > 0.0 ? sqrt(w2) : 1.0;
    memset(A, 0, N * N * sizeof *A);
    for (size_t r = 0; r < s; ++r) {
        A[r * N + s + r] = w;
        for (size_t q = 0; q < s; ++q) {
            A[(s + r) * N + q] = -S[r * s + q] / w;
            A[(s + r) * N + s + q] = -Cs[r * s + q];
        }
    }
    double vl_unused = 0.0;
    lapack_int n = (lapack_int)N;
    lapack_int info = LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'V', n, A, n, L->re, L->im, &vl_unused, 1, V, n);
    if (info != 0)
        return BK_FAIL(err, BK_ERR_SOLVER,
                       "exact stepper: the state-space eigenproblem of the %zu coupled pairs %zu..%zu failed "
                       "(LAPACK dgeev info %d)", s, members[0], members[s - 1], (int)info);
    /* V's LU and its condition first: everything below is V^-1 applied to known vectors,
     * and the eigenvalues themselves are only as good as V's conditioning (a Jordan block
     * splits its double eigenvalue by sqrt(eps), to either side of the axis). */
    memcpy(LU, V, N * N * sizeof *V);
    double norm = LAPACKE_dlange(LAPACK_ROW_MAJOR, '1', n, n, V, n);
    info = LAPACKE_dgetrf(LAPACK_ROW_MAJOR, n, n, LU, n, pivot);
    double rcond = 0.0;
    if (info == 0 && LAPACKE_dgecon(LAPACK_ROW_MAJOR, '1', n, LU, n, norm, &rcond) != 0)
        rcond = 0.0;
    if (info != 0 || !(rcond * COUPLED_MAX_CONDITION >= 1.0))
        return BK_FAIL(err, BK_ERR_CONFIG,
                       "method exact: the damped modes of the %zu slipping pairs %zu..%zu, coupled by dashpots "
                       "not proportional to their masses and springs, are nearly defective (their eigenvector "
                       "matrix's condition number %.3g exceeds %.3g: two modes merge, as at critical damping or "
                       "for an undamped free mode), so no modal solution is accurate" USE_INTEGRATOR,
                       s, members[0], members[s - 1], rcond > 0.0 ? 1.0 / rcond : INFINITY,
                       COUPLED_MAX_CONDITION);
    double l_max = 0.0;
    for (size_t j = 0; j < N; ++j)
        l_max = fmax(l_max, hypot(L->re[j], L->im[j]));
    for (size_t j = 0; j < N; ++j) {
        if (L->re[j] > ZERO_MODE * l_max / rcond)
            return BK_FAIL(err, BK_ERR_CONFIG,
                           "method exact: the damped pairs %zu..%zu have a growing mode (eigenvalue %.6g%+.6gi "
                           "/s): negative stiffness or damping" USE_INTEGRATOR,
                           members[0], members[s - 1], L->re[j], L->im[j]);
        if (L->re[j] > 0.0)
            L->re[j] = 0.0; /* rounding of a free or undamped mode */
    }
    /* G = V^-1 z'(0), z'(0) = M^(1/2) (v0, accel0); F = V^-1 (0, M^(1/2) b1). */
    for (size_t r = 0; r < s; ++r) {
        size_t i = members[r];
        double sm = eb->sqrt_mass[i];
        rhs[r] = w * sm * eb->y0[2 * i + 1];
        rhs[s + r] = sm * eb->accel0[i];
        rhs[N + r] = 0.0;
        rhs[N + s + r] = sm * eb->accel_rate[i];
    }
    /* two right-hand sides, stored as columns of an N x 2 row-major matrix */
    double *B = A; /* dgeev is done with A */
    for (size_t r = 0; r < N; ++r) {
        B[2 * r] = rhs[r];
        B[2 * r + 1] = rhs[N + r];
    }
    info = LAPACKE_dgetrs(LAPACK_ROW_MAJOR, 'N', n, 2, LU, n, pivot, B, 2);
    if (info != 0)
        return BK_FAIL(err, BK_ERR_SOLVER, "exact stepper: solving with the coupled modes failed (info %d)",
                       (int)info);
    for (size_t j = 0; j < N; ++j) {
        L->G[j] = B[2 * j];
        L->F[j] = B[2 * j + 1];
        L->dxi[j] = L->ixi[j] = 0.0;
    }
    for (size_t r = 0; r < s; ++r) {
        double inv = 1.0 / eb->sqrt_mass[members[r]];
        for (size_t j = 0; j < N; ++j) {
            L->Tq[r * N + j] = V[r * N + j] * inv / w;
            L->Tr[r * N + j] = V[(s + r) * N + j] * inv;
        }
    }
    for (size_t jq = 0; jq < eb->m; ++jq) {
        const double *Pj = &eb->P[jq * eb->p], *Qj = &eb->Q[jq * eb->p];
        for (size_t j = 0; j < N; ++j) {
            double pq = 0.0, qr = 0.0;
            for (size_t r = 0; r < s; ++r) {
                pq += Pj[members[r]] * L->Tq[r * N + j];
                qr += Qj[members[r]] * L->Tr[r * N + j];
            }
            L->Pq[jq * N + j] = pq;
            L->Qr[jq * N + j] = qr;
        }
    }
    /* b0 = accel0 + D v0, D v0 = M^(-1/2) Cs M^(1/2) v0 */
    for (size_t r = 0; r < s; ++r) {
        double dv = 0.0;
        for (size_t q = 0; q < s; ++q)
            dv += Cs[r * s + q] * eb->sqrt_mass[members[q]] * eb->y0[2 * members[q] + 1];
        L->b0[r] = eb->accel0[members[r]] + dv / eb->sqrt_mass[members[r]];
    }
    /* Sampling: a pair varies at |l|, a real mode decays at |l| (in the fast list until it
     * has decayed). */
    for (size_t j = 0; j < N; ++j) {
        if (L->im[j] != 0.0)
            *rate_max = fmax(*rate_max, hypot(L->re[j], L->im[j]));
        else if (L->re[j] < 0.0)
            eb->fast[eb->n_fast++] = -L->re[j];
    }
    return BK_OK;
}

int bk_exact_coupled_modes(exact_backend *eb, double *rate_max, bk_error *err)
{
    size_t total = 0, largest = 0;
    for (size_t k = 0; k < eb->n_clusters; ++k) {
        if (!eb->coupled[k])
            continue;
        size_t s = eb->first[k + 1] - eb->first[k];
        eb->coupled[k] = 1 + total;
        total += layout_size(s, eb->m);
        largest = s > largest ? s : largest;
    }
    if (eb->n_coupled == 0)
        return BK_OK;
    double *data = bk_fit_buffer(eb->coupled_data, &eb->coupled_cap, total + 1, sizeof *data);
    if (!data)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the coupled modes");
    eb->coupled_data = data;
    size_t N = 2 * largest;
    /* A, V, LU, two right-hand sides, the pivots (as many doubles) */
    double *work = bk_fit_buffer(eb->coupled_work, &eb->coupled_work_cap, 3 * N * N + 3 * N + 1, sizeof *work);
    if (!work)
        return BK_FAIL(err, BK_ERR_NOMEM, "exact stepper: out of memory for the coupled modes of %zu pairs",
                       largest);
    eb->coupled_work = work;
    for (size_t k = 0; k < eb->n_clusters; ++k) {
        if (!eb->coupled[k])
            continue;
        layout L = layout_at(eb, k);
        int rc = coupled_cluster(eb, k, &L, work, rate_max, err);
        if (rc != BK_OK)
            return rc;
    }
    return BK_OK;
}

void bk_exact_coupled_amplitudes(exact_backend *eb, double tau)
{
    double tau2 = tau * tau, tau3 = tau2 * tau;
    for (size_t k = 0; k < eb->n_clusters && eb->n_coupled > 0; ++k) {
        if (!eb->coupled[k])
            continue;
        layout L = layout_at(eb, k);
        for (size_t j = 0; j < L.N; ++j) {
            if (L.im[j] == 0.0) {
                double phi[4];
                bk_exact_exp_phis(L.re[j] * tau, phi);
                L.dxi[j] = L.G[j] * tau * phi[1] + L.F[j] * tau2 * phi[2];
                L.ixi[j] = L.G[j] * tau2 * phi[2] + L.F[j] * tau3 * phi[3];
                continue;
            }
            /* a pair: w = x - i y on columns j, j + 1 (dgeev puts Im l > 0 first) */
            double pr[4], pi[4];
            bk_exact_exp_phis_complex(L.re[j] * tau, L.im[j] * tau, pr, pi);
            double g_re = L.G[j], g_im = -L.G[j + 1], f_re = L.F[j], f_im = -L.F[j + 1];
            double d_re = (g_re * pr[1] - g_im * pi[1]) * tau + (f_re * pr[2] - f_im * pi[2]) * tau2;
            double d_im = (g_re * pi[1] + g_im * pr[1]) * tau + (f_re * pi[2] + f_im * pr[2]) * tau2;
            double i_re = (g_re * pr[2] - g_im * pi[2]) * tau2 + (f_re * pr[3] - f_im * pi[3]) * tau3;
            double i_im = (g_re * pi[2] + g_im * pr[2]) * tau2 + (f_re * pi[3] + f_im * pr[3]) * tau3;
            L.dxi[j] = d_re;
            L.dxi[j + 1] = -d_im;
            L.ixi[j] = i_re;
            L.ixi[j + 1] = -i_im;
            ++j;
        }
    }
}

void bk_exact_coupled_state(const exact_backend *eb, size_t cl, double *y)
{
    layout L = layout_at(eb, cl);
    const size_t *members = &eb->members[eb->first[cl]];
    for (size_t r = 0; r < L.s; ++r) {
        const double *tq = L.Tq + r * L.N, *tr = L.Tr + r * L.N;
        double u = 0.0, dv = 0.0;
        for (size_t j = 0; j < L.N; ++j) {
            u += tq[j] * L.dxi[j];
            dv += tr[j] * L.dxi[j];
        }
        size_t i = members[r];
        y[2 * i] = eb->y0[2 * i] + u;
        y[2 * i + 1] = eb->y0[2 * i + 1] + dv;
    }
}

double bk_exact_coupled_quadrature(const exact_backend *eb, size_t jq)
{
    double sum = 0.0;
    for (size_t k = 0; k < eb->n_clusters && eb->n_coupled > 0; ++k) {
        if (!eb->coupled[k])
            continue;
        layout L = layout_at(eb, k);
        const double *pq = L.Pq + jq * L.N, *qr = L.Qr + jq * L.N;
        for (size_t j = 0; j < L.N; ++j)
            sum += (pq[j] + qr[j]) * L.ixi[j];
    }
    return sum;
}

double bk_exact_coupled_dissipation(const exact_backend *eb, double tau)
{
    double sum = 0.0;
    for (size_t k = 0; k < eb->n_clusters && eb->n_coupled > 0; ++k) {
        if (!eb->coupled[k])
            continue;
        layout L = layout_at(eb, k);
        const size_t *members = &eb->members[eb->first[k]];
        const double *S = &eb->S[eb->offset[k]];
        double kinetic = 0.0, work = 0.0, potential = 0.0;
        for (size_t r = 0; r < L.s; ++r) {
            const double *tq = L.Tq + r * L.N, *tr = L.Tr + r * L.N;
            double u = 0.0, dv = 0.0, iu = 0.0;
            for (size_t j = 0; j < L.N; ++j) {
                u += tq[j] * L.dxi[j];
                dv += tr[j] * L.dxi[j];
                iu += tq[j] * L.ixi[j];
            }
            size_t i = members[r];
            double m = eb->problem.pair_mass[i];
            kinetic += m * dv * (2.0 * eb->y0[2 * i + 1] + dv);
            work += m * (L.b0[r] * u + eb->accel_rate[i] * (tau * u - iu));
            L.q[r] = eb->sqrt_mass[i] * u;
        }
        /* u^T M K u = q^T S q */
        for (size_t r = 0; r < L.s; ++r) {
            double row = 0.0;
            for (size_t c = 0; c < L.s; ++c)
                row += S[r * L.s + c] * L.q[c];
            potential += L.q[r] * row;
        }
        sum += -0.5 * kinetic - 0.5 * potential + work;
    }
    return sum;
}
