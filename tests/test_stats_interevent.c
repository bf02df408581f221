/* Interevent times (src/stats_interevent.c) on seeded synthetic catalogs with known answers:
 * a Poisson process rescales to the unit exponential (CV 1, gamma shape 1, density e^-theta)
 * at every magnitude threshold (the collapse), a gamma renewal process of shape 0.5 gives
 * back its shape and CV 1/sqrt(0.5); a changed shape is told apart.  Levels: 3 standard
 * errors for the fitted shape and the CV (about 1/sqrt(n) for CV = 1), 4 binomial standard
 * deviations for the density of every bin holding 100 or more intervals. */
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

enum { N = 20000 };

/* Events of a renewal process with gamma(shape, 1/shape) intervals (mean 1 s), magnitudes
 * GR with b = 1 from 2.0 up, drawn independently. */
static double renewal(gsl_rng *rng, double shape, double *t, double *m)
{
    double now = 0.0;
    for (size_t i = 0; i < N; ++i) {
        now += gsl_ran_gamma(rng, shape, 1.0 / shape);
        t[i] = now;
        m[i] = 1.95 + gsl_ran_exponential(rng, log10(exp(1.0)));
    }
    return now;
}

static void test_poisson(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 8);
    double *t = malloc(N * sizeof *t), *m = malloc(N * sizeof *m);
    assert_true(t && m);
    double span = renewal(rng, 1.0, t, m);
    bk_error err = {0};
    for (int k = 0; k < 3; ++k) {
        double m_min = 1.95 + (double)k; /* 20000, 2000, 200 events */
        bk_interevent ie;
        assert_int_equal(bk_interevent_build(t, m, N, m_min, span, 5, &ie, &err), BK_OK);
        double n = (double)ie.n_intervals;
        print_message("M >= %.2f: %zu events, R = %.5g, CV = %.4f, gamma shape %.4f +- %.4f, scale %.4f\n", m_min,
                      ie.n_events, ie.rate, ie.cv, ie.gamma_shape, ie.gamma_shape_sigma, ie.gamma_scale);
        assert_close(ie.rate, (double)ie.n_events / span, 1e-15, 0.0);
        assert_close(ie.cv, 1.0, 0.0, 3.0 / sqrt(n));
        assert_close(ie.gamma_shape, 1.0, 0.0, 3.0 * ie.gamma_shape_sigma);
        assert_close(ie.gamma_shape * ie.gamma_scale, 1.0, 0.0, 3.0 / sqrt(n)); /* mean theta */
        assert_int_equal(ie.n_zero, 0);
        /* The collapse: every threshold's density is the unit exponential's mean over each
         * bin, within 4 binomial sd (about 30 bins: a false alarm in 1 of 500), in every bin of
         * 100 intervals or more. */
        size_t checked = 0;
        for (size_t b = 0; b < ie.n_bins; ++b) {
            double lo = ie.theta[b] * pow(10.0, -0.1), hi = ie.theta[b] * pow(10.0, 0.1);
            double count = ie.density[b] * n * (hi - lo);
            if (count < 100.0)
                continue;
            double expected = (exp(-lo) - exp(-hi)) / (hi - lo);
            assert_close(ie.density[b], expected, 4.0 / sqrt(count), 0.0);
            ++checked;
        }
        assert_true(checked >= (k == 0 ? 10u : k == 1 ? 5u : 0u));
        bk_interevent_free(&ie);
    }
    free(t);
    free(m);
    gsl_rng_free(rng);
}

static void test_clustered(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 9);
    double *t = malloc(N * sizeof *t), *m = malloc(N * sizeof *m);
    assert_true(t && m);
    double span = renewal(rng, 0.5, t, m);
    bk_error err = {0};
    bk_interevent ie;
    assert_int_equal(bk_interevent_build(t, NULL, N, 0.0, span, 5, &ie, &err), BK_OK);
    print_message("gamma(0.5) renewal: CV = %.4f, shape %.4f +- %.4f\n", ie.cv, ie.gamma_shape, ie.gamma_shape_sigma);
    assert_close(ie.gamma_shape, 0.5, 0.0, 3.0 * ie.gamma_shape_sigma);
    assert_close(ie.cv, sqrt(2.0), 0.0, 0.05);
    /* Told apart from a Poisson process: the shape is 1 far outside its errors. */
    assert_true(fabs(ie.gamma_shape - 1.0) > 20.0 * ie.gamma_shape_sigma);
    bk_interevent_free(&ie);
    free(t);
    free(m);
    gsl_rng_free(rng);
}

static void test_errors(void **state)
{
    (void)state;
    bk_interevent ie;
    bk_error err = {0};
    const double t[] = {0.0, 1.0, 2.0, 3.0}, m[] = {1.0, 1.0, 1.0, 1.0};
    assert_int_equal(bk_interevent_build(t, m, 2, 0.0, 10.0, 5, &ie, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "at least 3"));
    assert_int_equal(bk_interevent_build(t, m, 4, 0.0, 0.0, 5, &ie, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "observed span is 0 s"));
    assert_int_equal(bk_interevent_build(t, m, 4, 0.0, 10.0, 5, &ie, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "all equal"));
    assert_int_equal(bk_interevent_build(t, m, 4, 0.0, 10.0, 0, &ie, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "bins per decade"));
    /* Events starting together: counted, left out of the fit and the bins. */
    const double together[] = {0.0, 1.0, 1.0, 2.5, 3.0, 3.0, 4.5};
    assert_int_equal(bk_interevent_build(together, NULL, 7, 0.0, 5.0, 5, &ie, &err), BK_OK);
    assert_int_equal(ie.n_zero, 2);
    assert_int_equal(ie.n_intervals, 6);
    double integral = 0.0;
    for (size_t b = 0; b < ie.n_bins; ++b)
        integral += ie.density[b] * ie.theta[b] * (pow(10.0, 0.1) - pow(10.0, -0.1));
    assert_close(integral, 1.0, 1e-12, 0.0); /* the density of the 4 positive intervals */
    bk_interevent_free(&ie);
}

/* The report: thresholds from Mc up by 0.5 while 30 events remain, in text, JSON and TSV. */
static void test_report(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 10);
    double *t = malloc(N * sizeof *t), *m = malloc(N * sizeof *m);
    assert_true(t && m);
    double span = renewal(rng, 1.0, t, m);
    bk_event_table table = {.n = 2000, .t_start = t, .magnitude = m, .t_reached = NAN};
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    opt.mc_auto = 0;
    opt.mc = 2.0;
    opt.bootstrap = 0;
    bk_stats_report *rep = NULL;
    bk_error err = {0};
    assert_int_equal(bk_stats_report_compute(&table, "poisson", &opt, &rep, &err), BK_OK);
    /* 2000 events: about 2000, 632, 200, 63 at or above 2.0, 2.5, 3.0, 3.5. */
    assert_int_equal(rep->n_interevent, 4);
    for (size_t k = 0; k < rep->n_interevent; ++k)
        assert_close(rep->interevent[k].m_min, 2.0 + 0.5 * (double)k, 0.0, 1e-12);
    assert_true(rep->interevent[3].n_events >= 30);
    FILE *f = tmpfile();
    assert_int_equal(bk_stats_report_text(rep, f, &err), BK_OK);
    assert_int_equal(bk_stats_report_json(rep, f, &err), BK_OK);
    char *text = written_text(f);
    assert_non_null(text);
    fclose(f);
    assert_non_null(strstr(text, "interevent times (Corral 2004"));
    assert_non_null(strstr(text, "\"interevent\": [{\"magnitude_min\": 2, \"n_events\": 2000, "));
    free(text);
    char dir[64];
    assert_int_equal(make_temp_dir(dir, sizeof dir, "bksim_interevent"), 0);
    assert_int_equal(bk_stats_report_tsv(rep, dir, &err), BK_OK);
    char path[128];
    snprintf(path, sizeof path, "%s/interevent.tsv", dir);
    assert_true(path_exists(path));
    assert_int_equal(remove_tree(dir), 0);
    bk_stats_report_free(rep);
    /* Twenty events: none, and the note says why. */
    table.n = 20;
    assert_int_equal(bk_stats_report_compute(&table, "poisson", &opt, &rep, &err), BK_OK);
    assert_int_equal(rep->n_interevent, 0);
    assert_non_null(strstr(rep->interevent_note, "fewer than 30 events at or above Mc = 2"));
    bk_stats_report_free(rep);
    (void)span;
    free(t);
    free(m);
    gsl_rng_free(rng);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_poisson),
        cmocka_unit_test(test_clustered),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_report),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
