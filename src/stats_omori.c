/* The Omori-Utsu law n(t) = K / (t + c)^p fitted by maximum likelihood to the times of a
 * sequence (Ogata, J. Phys. Earth 31, 115, 1983): events at t_i in [s, e] after their
 * mainshock, log-likelihood
 *
 *     l(K, c, p) = n ln K - p sum ln(t_i + c) - K A(c, p),
 *     A = ((e + c)^(1-p) - (s + c)^(1-p)) / (1 - p)   (ln((e + c)/(s + c)) at p = 1),
 *
 * maximised in K in closed form (K = n / A) and over (ln c, p) by GSL's Nelder-Mead simplex
 * from several starts, the best of them polished to a simplex of size 1e-10; standard errors
 * from the inverse of the observed information (the Hessian of l by central differences in
 * K, c, p).  The decay is judged by the likelihood
 * ratio against a constant rate, n / (e - s), with 2 degrees of freedom. */
#include "bksim/stats.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multimin.h>

/* Simplex sizes in (ln c, p): the starts run to COARSE_SIZE, the best of them to FINE_SIZE. */
#define COARSE_SIZE 1e-3
#define FINE_SIZE 1e-10

typedef struct sequence {
    const double *t;
    size_t n;
    double s, e;
} sequence;

/* The integral of (t + c)^-p over [s, e]. */
static double integral(const sequence *q, double c, double p)
{
    if (fabs(p - 1.0) < 1e-9)
        return log((q->e + c) / (q->s + c));
    return (pow(q->e + c, 1.0 - p) - pow(q->s + c, 1.0 - p)) / (1.0 - p);
}

static double log_likelihood(const sequence *q, double k, double c, double p)
{
    double sum = 0.0;
    for (size_t i = 0; i < q->n; ++i)
        sum += log(q->t[i] + c);
    return (double)q->n * log(k) - p * sum - k * integral(q, c, p);
}

/* Minus the profile log-likelihood (K = n / A) in x = (ln c, p). */
static double minus_profile(const gsl_vector *x, void *user)
{
    const sequence *q = user;
    double c = exp(gsl_vector_get(x, 0)), p = gsl_vector_get(x, 1);
    if (!(p > BK_OMORI_P_LOWEST && p < BK_OMORI_P_HIGHEST) || !(c > 0.0) || !isfinite(c))
        return GSL_POSINF;
    double a = integral(q, c, p);
    if (!(a > 0.0) || !isfinite(a))
        return GSL_POSINF;
    return -log_likelihood(q, (double)q->n / a, c, p);
}

/* The simplex from (ln c, p) with initial steps step_c, step_p until its size is below
 * tolerance (or 2000 iterations). */
static double simplex(const sequence *q, double log_c, double p, double step_c, double step_p, double tolerance,
                      double *best_log_c, double *best_p)
{
    gsl_multimin_function f = {minus_profile, 2, (void *)(uintptr_t)q};
    gsl_vector *x = gsl_vector_alloc(2), *step = gsl_vector_alloc(2);
    gsl_multimin_fminimizer *m = gsl_multimin_fminimizer_alloc(gsl_multimin_fminimizer_nmsimplex2, 2);
    double value = GSL_POSINF;
    if (x && step && m) {
        gsl_vector_set(x, 0, log_c);
        gsl_vector_set(x, 1, p);
        gsl_vector_set(step, 0, step_c);
        gsl_vector_set(step, 1, step_p);
        if (gsl_multimin_fminimizer_set(m, &f, x, step) == GSL_SUCCESS) {
            for (int it = 0; it < 2000; ++it) {
                if (gsl_multimin_fminimizer_iterate(m) != GSL_SUCCESS)
                    break;
                if (gsl_multimin_test_size(gsl_multimin_fminimizer_size(m), tolerance) == GSL_SUCCESS)
                    break;
            }
            value = m->fval;
            *best_log_c = gsl_vector_get(m->x, 0);
            *best_p = gsl_vector_get(m->x, 1);
        }
    }
    gsl_multimin_fminimizer_free(m);
    gsl_vector_free(x);
    gsl_vector_free(step);
    return value;
}

/* Standard errors of (K, c, p) from the observed information at the maximum. */
static void errors(const sequence *q, bk_omori *out)
{
    double v[3] = {out->k, out->c, out->p}, h[3];
    for (int i = 0; i < 3; ++i)
        h[i] = 1e-4 * fmax(fabs(v[i]), 1e-6);
    gsl_matrix *info = gsl_matrix_alloc(3, 3), *inverse = gsl_matrix_alloc(3, 3);
    gsl_permutation *perm = gsl_permutation_alloc(3);
    out->k_sigma = out->c_sigma = out->p_sigma = NAN;
    if (!info || !inverse || !perm)
        goto done;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double w[4];
            for (int s = 0; s < 4; ++s) {
                double x[3] = {v[0], v[1], v[2]};
                x[i] += (s & 1 ? -1.0 : 1.0) * h[i];
                x[j] += (s & 2 ? -1.0 : 1.0) * h[j];
                w[s] = x[1] > 0.0 && x[0] > 0.0 ? log_likelihood(q, x[0], x[1], x[2]) : NAN;
            }
            gsl_matrix_set(info, (size_t)i, (size_t)j, -(w[0] - w[1] - w[2] + w[3]) / (4.0 * h[i] * h[j]));
        }
    int sign = 0;
    if (gsl_linalg_LU_decomp(info, perm, &sign) != GSL_SUCCESS || gsl_linalg_LU_invert(info, perm, inverse) != GSL_SUCCESS)
        goto done;
    double var[3] = {gsl_matrix_get(inverse, 0, 0), gsl_matrix_get(inverse, 1, 1), gsl_matrix_get(inverse, 2, 2)};
    if (var[0] > 0.0 && var[1] > 0.0 && var[2] > 0.0) {
        out->k_sigma = sqrt(var[0]);
        out->c_sigma = sqrt(var[1]);
        out->p_sigma = sqrt(var[2]);
    }
done:
    gsl_permutation_free(perm);
    gsl_matrix_free(info);
    gsl_matrix_free(inverse);
}

int bk_omori_fit(const double *t, size_t n, double start, double end, bk_omori *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(isfinite(start) && isfinite(end) && start >= 0.0 && end > start))
        return BK_FAIL(err, BK_ERR_INVALID, "Omori fit: window [%g, %g] s after the mainshock: allowed 0 <= start < end",
                       start, end);
    if (n < BK_OMORI_MIN_EVENTS)
        return BK_FAIL(err, BK_ERR_INVALID, "Omori fit: %zu events in the window: needs at least %d", n,
                       BK_OMORI_MIN_EVENTS);
    for (size_t i = 0; i < n; ++i)
        if (!(t[i] >= start && t[i] <= end))
            return BK_FAIL(err, BK_ERR_INVALID, "Omori fit: event %zu at t = %g s lies outside the window [%g, %g] s",
                           i, t[i], start, end);
    sequence q = {t, n, start, end};
    /* A simplex that cannot contract or a singular information matrix is a result here (a
     * poor start, NaN errors), not a reason for GSL's default handler to abort the process. */
    gsl_error_handler_t *handler = gsl_set_error_handler_off();
    /* Starts across the plausible c (a millionth of the window to the window) and p. */
    double best = GSL_POSINF, log_c = 0.0, p = 1.0;
    const double c_starts[] = {1e-6, 1e-4, 1e-2, 1e-1, 1.0}, p_starts[] = {0.5, 1.0, 1.5};
    for (size_t i = 0; i < sizeof c_starts / sizeof c_starts[0]; ++i)
        for (size_t j = 0; j < sizeof p_starts / sizeof p_starts[0]; ++j) {
            double lc = 0.0, pp = 1.0;
            double value = simplex(&q, log(c_starts[i] * (end - start)), p_starts[j], 1.0, 0.2, COARSE_SIZE, &lc, &pp);
            if (value < best) {
                best = value;
                log_c = lc;
                p = pp;
            }
        }
    /* The starts only pick the basin: the best is polished to the final tolerance, once. */
    if (isfinite(best)) {
        double lc = log_c, pp = p;
        double value = simplex(&q, log_c, p, 0.05, 0.01, FINE_SIZE, &lc, &pp);
        if (value <= best) {
            best = value;
            log_c = lc;
            p = pp;
        }
    }
    if (!isfinite(best)) {
        gsl_set_error_handler(handler);
        return BK_FAIL(err, BK_ERR_INVALID, "Omori fit: the likelihood has no finite maximum for these %zu events", n);
    }
    out->n = n;
    out->start = start;
    out->end = end;
    out->c = exp(log_c);
    out->p = p;
    out->k = (double)n / integral(&q, out->c, p);
    out->log_likelihood = -best;
    /* Against a constant rate: l0 = n ln(n / (e - s)) - n. */
    double l0 = (double)n * log((double)n / (end - start)) - (double)n;
    out->lr = 2.0 * (out->log_likelihood - l0);
    out->decays = out->lr > BK_OMORI_LR_CHI2_2DOF_1PC && out->p > 0.0;
    errors(&q, out);
    gsl_set_error_handler(handler);
    return BK_OK;
}

static int compare_doubles(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

/* Ogata's residual analysis (SAPP's respoi): under the fitted law the transformed times
 * tau_i = Lambda(t_i) = K int_s^t_i (u + c)^-p du form a unit-rate Poisson process on
 * [0, Lambda(e)], so tau_i / Lambda(e) are uniform.  The parameters come from the same times,
 * which makes the asymptotic p-value conservative (Lilliefors' point): a small p is a misfit,
 * a large one is no proof of fit. */
int bk_omori_residual_check(const double *t, size_t n, const bk_omori *fit, bk_omori_residuals *out, bk_error *err)
{
    memset(out, 0, sizeof *out);
    if (n == 0 || !(fit->k > 0.0 && fit->c > 0.0 && isfinite(fit->p)))
        return BK_FAIL(err, BK_ERR_INVALID, "Omori residuals: %zu events and a fit with K = %g, c = %g, p = %g: "
                       "needs at least 1 event and K, c > 0", n, fit->k, fit->c, fit->p);
    sequence q = {t, n, fit->start, fit->end};
    out->tau = malloc(n * sizeof *out->tau);
    if (!out->tau)
        return BK_FAIL(err, BK_ERR_NOMEM, "Omori residuals: out of memory for %zu events", n);
    for (size_t i = 0; i < n; ++i) {
        if (!(t[i] >= fit->start && t[i] <= fit->end)) {
            bk_omori_residuals_free(out);
            return BK_FAIL(err, BK_ERR_INVALID, "Omori residuals: event %zu at t = %g s lies outside the fit's "
                           "window [%g, %g] s", i, t[i], fit->start, fit->end);
        }
        sequence upto = {t, n, fit->start, t[i]};
        out->tau[i] = fit->k * integral(&upto, fit->c, fit->p);
    }
    qsort(out->tau, n, sizeof *out->tau, compare_doubles);
    out->n = n;
    out->tau_end = fit->k * integral(&q, fit->c, fit->p);
    double d = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double u = out->tau[i] / out->tau_end;
        d = fmax(d, fmax((double)(i + 1) / (double)n - u, u - (double)i / (double)n));
    }
    double root = sqrt((double)n);
    out->d = d;
    out->p = bk_ks_q((root + 0.12 + 0.11 / root) * d);
    return BK_OK;
}

void bk_omori_residuals_free(bk_omori_residuals *res)
{
    free(res->tau);
    memset(res, 0, sizeof *res);
}
