/* The Omori-Utsu fit (src/stats_omori.c) on seeded synthetic sequences: non-homogeneous
 * Poisson processes of rate K / (t + c)^p drawn by inverting their cumulative rate, and a
 * homogeneous one.  Levels: the fitted p within 2 of its standard errors of the true p (0.8,
 * 1.0, 1.3; a calibrated error misses 1 time in 22), c and K within 3; the constant-rate
 * sequence is not called a decay (the likelihood-ratio test at 1 %), each Omori sequence is. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "bk_test.h"
#include "bksim/stats.h"

#define T_END 100.0

/* Times of K / (t + c)^p on [0, T_END]: a Poisson count of the integral, each time by
 * inverting the cumulative rate.  Returns how many (at most cap). */
static size_t omori_sequence(gsl_rng *rng, double k, double c, double p, double *t, size_t cap)
{
    double total = fabs(p - 1.0) < 1e-12 ? log((T_END + c) / c)
                                          : (pow(T_END + c, 1.0 - p) - pow(c, 1.0 - p)) / (1.0 - p);
    size_t n = gsl_ran_poisson(rng, k * total);
    if (n > cap)
        n = cap;
    for (size_t i = 0; i < n; ++i) {
        double y = gsl_rng_uniform(rng) * total;
        t[i] = fabs(p - 1.0) < 1e-12 ? c * exp(y) - c : pow(pow(c, 1.0 - p) + (1.0 - p) * y, 1.0 / (1.0 - p)) - c;
    }
    return n;
}

static void test_recovers(void **state)
{
    (void)state;
    enum { CAP = 10000 };
    static double t[CAP];
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 1983);
    const double ps[] = {0.8, 1.0, 1.3};
    bk_error err = {0};
    for (size_t k = 0; k < 3; ++k) {
        size_t n = omori_sequence(rng, 100.0, 0.01, ps[k], t, CAP);
        bk_omori fit;
        assert_int_equal(bk_omori_fit(t, n, 0.0, T_END, &fit, &err), BK_OK);
        print_message("p = %.1f: %zu events, K = %.4g +- %.3g, c = %.4g +- %.3g, p = %.4f +- %.4f, LR %.1f\n", ps[k],
                      n, fit.k, fit.k_sigma, fit.c, fit.c_sigma, fit.p, fit.p_sigma, fit.lr);
        assert_true(isfinite(fit.p_sigma) && fit.p_sigma > 0.0);
        assert_close(fit.p, ps[k], 0.0, 2.0 * fit.p_sigma);
        assert_close(fit.c, 0.01, 0.0, 3.0 * fit.c_sigma);
        assert_close(fit.k, 100.0, 0.0, 3.0 * fit.k_sigma);
        assert_true(fit.decays);
    }
    gsl_rng_free(rng);
}

static void test_poisson(void **state)
{
    (void)state;
    enum { N = 1000 };
    static double t[N];
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 4);
    for (size_t i = 0; i < N; ++i)
        t[i] = T_END * gsl_rng_uniform(rng);
    bk_error err = {0};
    bk_omori fit;
    assert_int_equal(bk_omori_fit(t, N, 0.0, T_END, &fit, &err), BK_OK);
    print_message("constant rate: p = %.4f, c = %.4g, LR %.2f (decay above %.2f)\n", fit.p, fit.c, fit.lr,
                  BK_OMORI_LR_CHI2_2DOF_1PC);
    assert_false(fit.decays);
    gsl_rng_free(rng);
}

/* Ogata's residual check: transformed by the true or fitted law, an Omori sequence is a
 * unit-rate Poisson process (KS p not small, the expected count matching n); transformed by a
 * law with the wrong p it is not (p < 0.01), so the check can fail. */
static void test_residuals(void **state)
{
    (void)state;
    enum { CAP = 10000 };
    static double t[CAP];
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 1987);
    size_t n = omori_sequence(rng, 100.0, 0.01, 1.1, t, CAP);
    bk_error err = {0};
    bk_omori fit;
    assert_int_equal(bk_omori_fit(t, n, 0.0, T_END, &fit, &err), BK_OK);
    bk_omori_residuals res;
    assert_int_equal(bk_omori_residual_check(t, n, &fit, &res, &err), BK_OK);
    print_message("fitted: %zu events, expected %.2f, KS D = %.4f, p = %.3f\n", n, res.tau_end, res.d, res.p);
    assert_int_equal(res.n, n);
    /* K = n / A: the fitted law expects exactly the events it was fitted to. */
    assert_close(res.tau_end, (double)n, 1e-9, 0.0);
    assert_true(res.p > 0.05);
    for (size_t i = 1; i < n; ++i)
        assert_true(res.tau[i] >= res.tau[i - 1]);
    bk_omori_residuals_free(&res);

    bk_omori wrong = fit;
    wrong.p = fit.p - 0.3;
    double a = (pow(T_END + wrong.c, 1.0 - wrong.p) - pow(wrong.c, 1.0 - wrong.p)) / (1.0 - wrong.p);
    wrong.k = (double)n / a;
    assert_int_equal(bk_omori_residual_check(t, n, &wrong, &res, &err), BK_OK);
    print_message("p lowered by 0.3: KS D = %.4f, p = %.3g\n", res.d, res.p);
    assert_true(res.p < 0.01);
    bk_omori_residuals_free(&res);

    double outside = T_END + 1.0;
    assert_int_equal(bk_omori_residual_check(&outside, 1, &fit, &res, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "lies outside the fit's window"));
    assert_null(res.tau);
    gsl_rng_free(rng);
}

static void test_errors(void **state)
{
    (void)state;
    double t[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    bk_omori fit;
    bk_error err = {0};
    assert_int_equal(bk_omori_fit(t, 9, 0.0, 20.0, &fit, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "9 events in the window: needs at least 10"));
    assert_int_equal(bk_omori_fit(t, 12, 5.0, 20.0, &fit, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "event 0 at t = 1 s lies outside the window [5, 20] s"));
    assert_int_equal(bk_omori_fit(t, 12, 20.0, 20.0, &fit, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "allowed 0 <= start < end"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_recovers),
        cmocka_unit_test(test_poisson),
        cmocka_unit_test(test_residuals),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
