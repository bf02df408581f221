/* The exact stepper's output rows in O(size) per cluster.  Summing a cluster's modes back to
 * its pairs costs size^2 per row, which a long slipping stretch sampled densely pays over and
 * over.  Between transitions the motion solves the linear u'' = -K u + a0 + a1 tau, so about
 * the last step end tc (an exact modal state) it is the Taylor series
 *
 *     x(tc + s) = sum_n d_n s^n / n!,   d_0 = x, d_1 = v, d_2 = a0 + a1 tau_c - K u,
 *                                       d_3 = a1 - K v,  d_{n+2} = -K d_n,
 *
 * whose terms cost one sparse product each (K has O(size) entries).  A row lies inside the
 * last step, |s| <= h <= 2 pi / (16 w_max), so rho = w s <= 0.4 and |d_{n+2}| <= w^2 |d_n|
 * (in the mass-weighted norm): the series is summed until the rest is below 2^-60 of its
 * leading term, 14 terms at most in practice, and the row is the closed form's to rounding.
 * The quadratures keep the modal form, O(m p) already (with every mode's sines, about half
 * of a series row's cost).  Small clusters keep the modal sum, cheaper below
 * SERIES_MIN_PAIRS.
 *
 * With dashpots (D = M^-1 C, proportional or coupling the modes) the motion solves
 * u'' = -K u - D (v - v0) + a0 + a1 tau, and the series is
 *
 *     d_2 = a0 + a1 tau_c - K u - D (v - v0),  d_3 = a1 - K v - D d_2,
 *     d_{n+2} = -K d_n - D d_{n+1},
 *
 * two sparse products a term.  In the energy norm (x^T M K x + v^T M v) the state matrix
 * [0 I; -K -D] has norm at most w + g, w^2 and g the Gershgorin bounds of
 * M^(1/2) K M^(-1/2) and M^(1/2) D M^(-1/2), so with rho = (w + g) |s| the terms shrink as
 * rho^n / n! against the leading one; a row within the last step has rho <= 1.3 at
 * worst (a damping ratio of 1 on the fastest mode; the step is 2 pi / 16 over the fastest
 * root), and the series is summed while rho < 2, else the modal sum serves. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "exact_backend.h"

/* Below this many pairs a cluster's modal sum (2 size^2 products) is cheaper than the series
 * (about 14 sparse products of 3 entries per pair plus its sums): bench/exact_rows.c
 * measured them equal at 64 pairs, the series 1.7x faster at 128 and about 30x at 2048. */
#define SERIES_MIN_PAIRS 64
#define SERIES_MAX_TERMS 64
#define SERIES_REST 0x1p-60

/* D's rows of the damped series clusters, compressed as K's, and each such cluster's rate
 * bound w + g (the header): Gershgorin on M^(1/2) K M^(-1/2) and M^(1/2) D M^(-1/2), whose
 * entries are K's and D's times sqrt(m_row / m_col). */
static int damped_rows(exact_backend *eb, bk_error *err)
{
    size_t p = eb->p, *start = eb->damp_start, entries = 0;
    memset(start, 0, (p + 1) * sizeof *start);
    const coupling *dampings = eb->shared->dampings;
    for (size_t e = 0; e < eb->n_dampings; ++e) {
        size_t i = dampings[e].row;
        if (eb->series[eb->cluster_of[i]] == 2) {
            start[i + 1]++;
            entries++;
        }
    }
    for (size_t i = 0; i < p; ++i)
        start[i + 1] += start[i];
    size_t *col = bk_fit_buffer(eb->damp_col, &eb->damp_col_cap, entries + 1, sizeof *col);
    if (col)
        eb->damp_col = col;
    double *value = col ? bk_fit_buffer(eb->damp_value, &eb->damp_value_cap, entries + 1, sizeof *value) : NULL;
    if (!value)
        return BK_FAIL(err, BK_ERR_NOMEM,
                       "exact stepper: out of memory for the %zu dashpots of the rows' series", entries);
    eb->damp_value = value;
    for (size_t e = 0; e < eb->n_dampings; ++e) {
        size_t i = dampings[e].row;
        if (eb->series[eb->cluster_of[i]] != 2)
            continue;
        size_t slot = start[i]++;
        eb->damp_col[slot] = dampings[e].col;
        eb->damp_value[slot] = dampings[e].value;
    }
    for (size_t i = p; i > 0; --i)
        start[i] = start[i - 1];
    start[0] = 0;
    for (size_t cl = 0; cl < eb->n_clusters; ++cl) {
        if (eb->series[cl] != 2)
            continue;
        double k_bound = 0.0, d_bound = 0.0;
        for (size_t r = eb->first[cl]; r < eb->first[cl + 1]; ++r) {
            size_t i = eb->members[r];
            double k_row = 0.0, d_row = 0.0;
            for (size_t e = eb->row_start[i]; e < eb->row_start[i + 1]; ++e)
                k_row += fabs(eb->row_value[e]) * eb->sqrt_mass[i] / eb->sqrt_mass[eb->row_col[e]];
            for (size_t e = start[i]; e < start[i + 1]; ++e)
                d_row += fabs(eb->damp_value[e]) * eb->sqrt_mass[i] / eb->sqrt_mass[eb->damp_col[e]];
            k_bound = fmax(k_bound, k_row);
            d_bound = fmax(d_bound, d_row);
        }
        eb->cluster_omega[cl] = sqrt(k_bound) + d_bound;
    }
    return BK_OK;
}

int bk_exact_rows_prepare(exact_backend *eb, bk_error *err)
{
    eb->n_series = 0;
    size_t entries = 0;
    for (size_t cl = 0; cl < eb->n_clusters; ++cl) {
        size_t first = eb->first[cl], size = eb->first[cl + 1] - first;
        int damped = eb->coupled[cl] != 0;
        for (size_t k = first; k < first + size; ++k)
            damped |= eb->gamma[k] != 0.0;
        eb->series[cl] = !eb->uniform[cl] && size >= SERIES_MIN_PAIRS ? (damped ? 2 : 1) : 0;
        if (!eb->series[cl])
            continue;
        eb->n_series++;
        double omega = 0.0;
        for (size_t k = first; k < first + size; ++k)
            omega = fmax(omega, eb->omega[k]);
        eb->cluster_omega[cl] = omega; /* a damped cluster's bound below */
    }
    if (eb->n_series == 0)
        return BK_OK;
    /* K's rows of the series clusters, compressed: counts, offsets, then the entries. */
    size_t p = eb->p, *start = eb->row_start;
    memset(start, 0, (p + 1) * sizeof *start);
    const coupling *couplings = eb->shared->couplings;
    for (size_t e = 0; e < eb->n_couplings; ++e) {
        size_t i = couplings[e].row;
        if (eb->series[eb->cluster_of[i]]) {
            start[i + 1]++;
            entries++;
        }
    }
    for (size_t i = 0; i < p; ++i)
        start[i + 1] += start[i];
    size_t *col = bk_fit_buffer(eb->row_col, &eb->row_col_cap, entries + 1, sizeof *col);
    if (col)
        eb->row_col = col;
    double *value = col ? bk_fit_buffer(eb->row_value, &eb->row_value_cap, entries + 1, sizeof *value) : NULL;
    if (!value)
        return BK_FAIL(err, BK_ERR_NOMEM,
                       "exact stepper: out of memory for the %zu couplings of the rows' series", entries);
    eb->row_value = value;
    /* Fill row by row; start[i] walks forward and is restored from start[i + 1] after. */
    for (size_t e = 0; e < eb->n_couplings; ++e) {
        size_t i = couplings[e].row;
        if (!eb->series[eb->cluster_of[i]])
            continue;
        size_t slot = start[i]++;
        eb->row_col[slot] = couplings[e].col;
        eb->row_value[slot] = couplings[e].value;
    }
    for (size_t i = p; i > 0; --i)
        start[i] = start[i - 1];
    start[0] = 0;
    return damped_rows(eb, err);
}

/* -(K w)_i for the members of one cluster: d_{n+2} from d_n. */
static void minus_stiffness_times(const exact_backend *eb, const size_t *members, size_t size,
                            const double *w, double *out)
{
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        double sum = 0.0;
        for (size_t e = eb->row_start[i]; e < eb->row_start[i + 1]; ++e)
            sum += eb->row_value[e] * w[eb->row_col[e]];
        out[i] = -sum;
    }
}

/* -(K w + D z)_i for the members of one damped cluster: d_{n+2} from d_n and d_{n+1}. */
static void minus_damped_times(const exact_backend *eb, const size_t *members, size_t size, const double *w,
                               const double *z, double *out)
{
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        double sum = 0.0;
        for (size_t e = eb->row_start[i]; e < eb->row_start[i + 1]; ++e)
            sum += eb->row_value[e] * w[eb->row_col[e]];
        for (size_t e = eb->damp_start[i]; e < eb->damp_start[i + 1]; ++e)
            sum += eb->damp_value[e] * z[eb->damp_col[e]];
        out[i] = -sum;
    }
}

/* A damped cluster's pairs at tc + s from its series (the header); 0 if s is too far. */
static int damped_series_state(exact_backend *eb, size_t cl, double s, double *y)
{
    double rho = eb->cluster_omega[cl] * fabs(s);
    if (!(rho < 2.0))
        return 0;
    size_t first = eb->first[cl], size = eb->first[cl + 1] - first;
    const size_t *members = &eb->members[first];
    const double *yc = eb->yc, *y0 = eb->y0;
    /* d_n in prev, d_{n+1} in cur, d_{n+2} into next; u and v - v0 at tc in next_odd */
    double *prev = eb->even, *cur = eb->odd, *next = eb->next_even, *dv = eb->next_odd;
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        next[i] = yc[2 * i] - y0[2 * i];
        dv[i] = yc[2 * i + 1] - y0[2 * i + 1];
    }
    minus_damped_times(eb, members, size, next, dv, prev);
    double tau_c = eb->tc - eb->t0;
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        prev[i] += eb->accel0[i] + eb->accel_rate[i] * tau_c; /* d_2 */
        dv[i] = yc[2 * i + 1];                                /* v, for d_3 */
    }
    minus_damped_times(eb, members, size, dv, prev, cur);
    double fn = 0.5 * s * s, fv = s; /* s^n / n!, s^(n-1) / (n-1)! for n = 2 */
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        cur[i] += eb->accel_rate[i]; /* d_3 */
        y[2 * i] = prev[i] * fn;
        y[2 * i + 1] = prev[i] * fv;
    }
    /* after term n, what is left of the velocities' series relative to its leading term
     * (|d_k| <= (w + g)^(k-2) max(|d_2|, |d_3| / (w + g)), term k of the velocities
     * d_k s^(k-1) / (k-1)!): at most 2 rho^(n-1) / n! for n >= 3, rho < 2; rho at n = 2 */
    double rest = rho;
    for (int n = 3; n < SERIES_MAX_TERMS; ++n) {
        fv = fn;
        fn *= s / (double)n;
        for (size_t r = 0; r < size; ++r) {
            size_t i = members[r];
            y[2 * i] += cur[i] * fn;
            y[2 * i + 1] += cur[i] * fv;
        }
        rest *= rho / (double)n;
        if (rest <= SERIES_REST)
            break;
        minus_damped_times(eb, members, size, prev, cur, next);
        double *swap = prev;
        prev = cur, cur = next, next = swap;
    }
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        y[2 * i] = yc[2 * i] + (yc[2 * i + 1] * s + y[2 * i]);
        y[2 * i + 1] = yc[2 * i + 1] + y[2 * i + 1];
    }
    return 1;
}

/* Cluster cl's pairs at tc + s from the series; 0 if s is too far from tc for it. */
static int series_state(exact_backend *eb, size_t cl, double s, double *y)
{
    if (eb->series[cl] == 2)
        return damped_series_state(eb, cl, s, y);
    double rho = eb->cluster_omega[cl] * fabs(s);
    if (!(rho < 1.0))
        return 0;
    size_t first = eb->first[cl], size = eb->first[cl + 1] - first;
    const size_t *members = &eb->members[first];
    const double *yc = eb->yc, *y0 = eb->y0;
    double *even = eb->even, *odd = eb->odd, *next_even = eb->next_even, *next_odd = eb->next_odd;
    /* d_2 and d_3 need K u and K v at tc. */
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        next_even[i] = yc[2 * i] - y0[2 * i];
        next_odd[i] = yc[2 * i + 1];
    }
    minus_stiffness_times(eb, members, size, next_even, even);
    minus_stiffness_times(eb, members, size, next_odd, odd);
    double tau_c = eb->tc - eb->t0;
    double f2 = 0.5 * s * s, f3 = f2 * s / 3.0; /* s^n / n! */
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        even[i] += eb->accel0[i] + eb->accel_rate[i] * tau_c;
        odd[i] += eb->accel_rate[i];
        /* The tails (terms n >= 2) first, so that the small terms add up among themselves. */
        y[2 * i] = even[i] * f2 + odd[i] * f3;
        y[2 * i + 1] = even[i] * s + odd[i] * f2;
    }
    /* Rest after the terms up to n + 1, relative to the leading one: 2 rho^n / (n + 2)!. */
    double fn1 = f3, rest = rho * rho / 12.0; /* fn1 = s^(n+1) / (n+1)! */
    for (int n = 2; rest > SERIES_REST && n + 3 < SERIES_MAX_TERMS; n += 2) {
        minus_stiffness_times(eb, members, size, even, next_even);
        minus_stiffness_times(eb, members, size, odd, next_odd);
        double fa = fn1 * s / (double)(n + 2), fb = fa * s / (double)(n + 3);
        for (size_t r = 0; r < size; ++r) {
            size_t i = members[r];
            y[2 * i] += next_even[i] * fa + next_odd[i] * fb;
            y[2 * i + 1] += next_even[i] * fn1 + next_odd[i] * fa;
        }
        double *swap = even;
        even = next_even, next_even = swap;
        swap = odd, odd = next_odd, next_odd = swap;
        fn1 = fb;
        rest *= rho * rho / ((double)(n + 3) * (double)(n + 4));
    }
    for (size_t r = 0; r < size; ++r) {
        size_t i = members[r];
        y[2 * i] = yc[2 * i] + (yc[2 * i + 1] * s + y[2 * i]);
        y[2 * i + 1] = yc[2 * i + 1] + y[2 * i + 1];
    }
    return 1;
}

void bk_exact_row_state(exact_backend *eb, double t, double *y)
{
    if (eb->n_series == 0 || !(fabs(t - eb->tc) <= eb->h)) {
        bk_exact_state(eb, t, y);
        return;
    }
    double tau = t - eb->t0;
    bk_exact_modal_amplitudes(eb, tau);
    for (size_t cl = 0; cl < eb->n_clusters; ++cl)
        if (!eb->series[cl] || !series_state(eb, cl, t - eb->tc, y))
            bk_exact_cluster_state(eb, cl, y);
    bk_exact_quadratures(eb, tau, y);
}
