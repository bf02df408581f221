/* Goodness of fit and bootstrap errors (src/stats_fit.c) on seeded synthetic catalogs, and
 * the report's refusals (src/stats_report.c) on catalogs that cannot support a b-value.
 *
 * Levels, stated: on 100 Gutenberg-Richter samples (b = 1, 500 magnitudes each, bins of 0.1
 * from Mc = 2.0; 200 bootstrap samples each) the true b lies within 2 bootstrap errors of the
 * estimate in at least 89 (95.4 expected of a calibrated error, 3 sd below), and the
 * goodness-of-fit p-value is about uniform: p < 0.1 in 2-20 of them (10 expected, about 3 sd
 * either way), p < 0.01 in at most 5.  tests/long/test_stats_calibration.c runs 2,000 such
 * samples for the rates themselves.  The test has power: a lognormal sample of 5,000 and a
 * flat one are rejected at p < 0.01, and so are lognormal potencies against the power law.
 * Measured values are printed. */
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
#include "files.h"

#define N_SAMPLES 100
#define SAMPLE_SIZE 500
#define SYNTHETIC 200

/* n magnitudes >= 1.95 with slope b, continuous (binned by the estimators). */
static void gr_magnitudes(gsl_rng *rng, double b, size_t n, double *m)
{
    for (size_t i = 0; i < n; ++i)
        m[i] = 1.95 + gsl_ran_exponential(rng, log10(exp(1.0)) / b);
}

static void test_gr_samples(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 33);
    double m[SAMPLE_SIZE];
    bk_b_options opt = {0.1, 0, 2.0, BK_MAXC_CORRECTION};
    size_t covered = 0, below_01 = 0, below_001 = 0;
    bk_error err = {0};
    for (size_t s = 0; s < N_SAMPLES; ++s) {
        gr_magnitudes(rng, 1.0, SAMPLE_SIZE, m);
        bk_b_estimate est;
        assert_int_equal(bk_b_value(m, SAMPLE_SIZE, 2.0, 0.1, &est, &err), BK_OK);
        bk_b_spread spread;
        assert_int_equal(bk_b_bootstrap(m, SAMPLE_SIZE, &opt, SYNTHETIC, 1000 + s, &spread, &err), BK_OK);
        assert_int_equal(spread.n_used, SYNTHETIC);
        assert_close(spread.b_sigma, est.sigma, 0.3, 0.0); /* beside Shi & Bolt */
        assert_true(spread.mc_sigma == 0.0);               /* a given Mc does not move */
        covered += fabs(est.b - 1.0) <= 2.0 * spread.b_sigma;
        bk_gof gof;
        assert_int_equal(bk_gr_gof(m, SAMPLE_SIZE, &est, SYNTHETIC, 2000 + s, &gof, &err), BK_OK);
        assert_int_equal(gof.n, SAMPLE_SIZE);
        below_01 += gof.p < 0.1;
        below_001 += gof.p < 0.01;
    }
    print_message("b within 2 bootstrap errors in %zu of %d samples; GoF p < 0.1 in %zu, p < 0.01 in %zu\n",
                  covered, N_SAMPLES, below_01, below_001);
    assert_true(covered >= 89);
    assert_true(below_01 >= 2 && below_01 <= 20);
    assert_true(below_001 <= 5);
    gsl_rng_free(rng);
}

/* The same seed, the same p-value and errors; Mc re-estimated moves with the resample. */
static void test_reproducible(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 5);
    double m[SAMPLE_SIZE + 300];
    gr_magnitudes(rng, 1.2, SAMPLE_SIZE, m);
    for (size_t i = SAMPLE_SIZE; i < SAMPLE_SIZE + 300; ++i) /* an incomplete tail below 1.95 */
        m[i] = 1.95 - 0.5 * gsl_rng_uniform(rng);
    bk_error err = {0};
    bk_b_estimate est;
    assert_int_equal(bk_b_value(m, SAMPLE_SIZE + 300, 2.0, 0.1, &est, &err), BK_OK);
    bk_gof a, b;
    assert_int_equal(bk_gr_gof(m, SAMPLE_SIZE + 300, &est, 300, 9, &a, &err), BK_OK);
    assert_int_equal(bk_gr_gof(m, SAMPLE_SIZE + 300, &est, 300, 9, &b, &err), BK_OK);
    assert_true(a.d == b.d && a.p == b.p);
    bk_b_options opt = {0.1, 1, 0.0, BK_MAXC_CORRECTION};
    bk_b_spread s1, s2;
    assert_int_equal(bk_b_bootstrap(m, SAMPLE_SIZE + 300, &opt, 300, 4, &s1, &err), BK_OK);
    assert_int_equal(bk_b_bootstrap(m, SAMPLE_SIZE + 300, &opt, 300, 4, &s2, &err), BK_OK);
    assert_true(s1.b_sigma == s2.b_sigma && s1.mc_sigma == s2.mc_sigma);
    print_message("Mc by maximum curvature, bootstrap: b +- %.4f, Mc +- %.4f\n", s1.b_sigma, s1.mc_sigma);
    assert_true(s1.mc_sigma >= 0.0 && s1.b_sigma > 0.0);
    assert_int_equal(bk_gr_gof(m, SAMPLE_SIZE, &est, 0, 9, &a, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "bootstrap samples 0: allowed 1 .."));
    gsl_rng_free(rng);
}

/* Curved distributions are told apart from a GR law, and lognormal potencies from a power
 * law; a true power law passes. */
static void test_power(void **state)
{
    (void)state;
    enum { N = 5000 };
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 11);
    double *m = malloc(N * sizeof *m);
    assert_non_null(m);
    bk_error err = {0};
    /* Lognormal magnitudes (log10 M normal) from 2.0 up. */
    for (size_t i = 0; i < N; ++i)
        m[i] = 2.0 + gsl_ran_lognormal(rng, -1.0, 0.5);
    bk_b_estimate est;
    assert_int_equal(bk_b_value(m, N, 2.0, 0.1, &est, &err), BK_OK);
    bk_gof gof;
    assert_int_equal(bk_gr_gof(m, N, &est, 500, 3, &gof, &err), BK_OK);
    print_message("lognormal magnitudes: D = %.4f, p = %.3g\n", gof.d, gof.p);
    assert_true(gof.p < BK_GOF_LEVEL);
    /* Potencies: a power law of alpha = 1.8 passes, lognormal ones do not. */
    for (size_t i = 0; i < N; ++i)
        m[i] = pow(gsl_rng_uniform_pos(rng), -1.0 / 0.8);
    bk_power_law fit;
    assert_int_equal(bk_power_law_mle(m, N, 1.0, &fit, &err), BK_OK);
    assert_int_equal(bk_power_law_gof(m, N, &fit, 500, 3, &gof, &err), BK_OK);
    print_message("power-law potencies: alpha = %.4f, D = %.4f, p = %.3g\n", fit.alpha, gof.d, gof.p);
    assert_close(fit.alpha, 1.8, 0.0, 3.0 * fit.sigma);
    assert_true(gof.p >= BK_GOF_LEVEL);
    for (size_t i = 0; i < N; ++i)
        m[i] = gsl_ran_lognormal(rng, 0.0, 1.0);
    assert_int_equal(bk_power_law_mle(m, N, 1.0, &fit, &err), BK_OK);
    assert_int_equal(bk_power_law_gof(m, N, &fit, 500, 3, &gof, &err), BK_OK);
    print_message("lognormal potencies above 1: D = %.4f, p = %.3g\n", gof.d, gof.p);
    assert_true(gof.p < BK_GOF_LEVEL);
    free(m);
    gsl_rng_free(rng);
}

/* The report on catalogs without a b-value: why, in text and JSON (null and a reason). */
static void expect_no_b(const double *m, size_t n, const char *reason)
{
    double *t = malloc(n * sizeof *t);
    assert_non_null(t);
    for (size_t i = 0; i < n; ++i)
        t[i] = (double)i;
    bk_event_table table = {.n = n, .t_start = t, .magnitude = (double *)(uintptr_t)m, .t_reached = NAN};
    bk_stats_report *rep = NULL;
    bk_error err = {0};
    assert_int_equal(bk_stats_report_compute(&table, "synthetic", NULL, &rep, &err), BK_OK);
    assert_false(rep->have_b);
    if (!strstr(rep->b_note, reason))
        print_error("note: %s\nexpected: %s\n", rep->b_note, reason);
    assert_non_null(strstr(rep->b_note, reason));
    FILE *f = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, f, &err), BK_OK);
    assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
    char *text = written_text(f);
    assert_non_null(text);
    fclose(f);
    assert_non_null(strstr(text, "b-value: not available: "));
    assert_non_null(strstr(text, "\"b_value\": null"));
    assert_non_null(strstr(text, "\"b_value_note\": \""));
    free(text);
    bk_stats_report_free(rep);
    free(t);
}

static void test_report_refuses(void **state)
{
    (void)state;
    /* Two events (bk10_coulomb.ini's catalog once printed b = 8.69 +- 0 from these). */
    const double two[] = {-3.1, -3.1};
    expect_no_b(two, 2, "at least 10");
    /* One bin at and above Mc: 30 events at 1.0 put Mc (maximum curvature + 0.2) at 1.2,
     * where the 12 others all are. */
    double one_bin[42];
    for (size_t i = 0; i < 42; ++i)
        one_bin[i] = i < 30 ? 1.0 + 0.001 * (double)i : 1.2 + 0.001 * (double)(i - 30);
    expect_no_b(one_bin, 42, "all 12 magnitudes at or above Mc = 1.2 fall in one bin");
    /* Flat: uniform magnitudes over two units (once b = 0.683 +- 0.006). */
    enum { N = 5000 };
    double *flat = malloc(N * sizeof *flat);
    assert_non_null(flat);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 17);
    for (size_t i = 0; i < N; ++i)
        flat[i] = 1.0 + 2.0 * gsl_rng_uniform(rng);
    expect_no_b(flat, N, "are not Gutenberg-Richter distributed");
    /* A true GR catalog of 5,000 keeps its b, with the test's verdict and the errors. */
    gr_magnitudes(rng, 1.0, N, flat);
    double *t = malloc(N * sizeof *t);
    assert_non_null(t);
    for (size_t i = 0; i < N; ++i)
        t[i] = (double)i;
    bk_event_table table = {.n = N, .t_start = t, .magnitude = flat, .t_reached = NAN};
    bk_stats_report *rep = NULL;
    bk_error err = {0};
    assert_int_equal(bk_stats_report_compute(&table, "gr", NULL, &rep, &err), BK_OK);
    assert_true(rep->have_b && rep->have_gr_gof && rep->have_b_spread);
    assert_false(rep->b_small_sample);
    print_message("GR catalog: b = %.4f +- %.4f (bootstrap %.4f), Mc = %g +- %.3f, GoF p = %.3g\n", rep->b.b,
                  rep->b.sigma, rep->b_spread.b_sigma, rep->mc, rep->b_spread.mc_sigma, rep->gr_gof.p);
    assert_close(rep->b.b, 1.0, 0.0, 3.0 * rep->b_spread.b_sigma);
    assert_true(rep->gr_gof.p >= BK_GOF_LEVEL);
    bk_stats_report_free(rep);
    /* 30 of them: a b-value, with the small-sample warning. */
    table.n = 30;
    assert_int_equal(bk_stats_report_compute(&table, "gr", NULL, &rep, &err), BK_OK);
    if (rep->have_b) {
        assert_true(rep->b_small_sample);
        FILE *f = tmpfile();
        assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
        char *text = written_text(f);
        assert_non_null(text);
        fclose(f);
        assert_non_null(strstr(text, "\"b_value_small_sample\": true"));
        free(text);
    }
    bk_stats_report_free(rep);
    free(t);
    free(flat);
    gsl_rng_free(rng);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gr_samples),
        cmocka_unit_test(test_reproducible),
        cmocka_unit_test(test_power),
        cmocka_unit_test(test_report_refuses),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
