/* b-positive, its a-value, the classic binned b, Mc by b-value stability and by the KS method
 * (src/stats_positive.c, src/stats_mc.c) against SeismoStats' published values (swiss-seismological-service/
 * SeismoStats 4605c4e: docstrings and tests of seismostats/analysis/bvalue/positive.py,
 * avalue/positive.py, bvalue/classic.py, estimate_mc.py, tests/test_estimate_mc.py), to the
 * precision they print, and on seeded synthetic catalogs: b-positive recovers b where a
 * short-term incompleteness after large events biases the classic b. */
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

#define N_OF(a) (sizeof(a) / sizeof((a)[0]))
#define LN_10 2.302585092994046

/* The docstring example of BPositiveBValueEstimator and ClassicBValueEstimator. */
static const double DOC24[] = {2.0, 2.5, 2.1, 2.2, 2.5, 2.2, 2.6, 2.3, 2.7, 2.2, 2.4, 2.0,
                               2.7, 2.2, 2.3, 2.1, 2.4, 2.6, 2.2, 2.2, 2.7, 2.4, 2.2, 2.5};
/* tests/test_estimate_mc.py, MAGNITUDES (also test_stats.c's MAXC_EXAMPLE). */
static const double MAGNITUDES[] = {
    2.3, 1.2, 1.5, 1.2, 1.7, 1.1, 1.2, 1.5, 1.8, 1.6, 1.2, 1.5, 1.2, 1.7, 1.6, 1.1, 1.1, 1.2, 2.0, 1.1,
    1.2, 1.1, 1.2, 1.6, 1.9, 1.3, 1.7, 1.3, 1.0, 1.2, 1.7, 1.3, 1.3, 1.1, 1.5, 1.4, 1.1, 2.1, 1.2, 2.2,
    1.7, 1.6, 1.1, 2.0, 2.1, 1.2, 1.0, 1.5, 1.2, 1.7, 1.8, 1.1, 1.3, 1.1, 1.3, 1.4, 2.1, 2.0, 1.1, 2.2,
    1.8, 1.4, 1.1, 1.0, 2.0, 2.0, 1.1, 1.0, 1.0, 1.5, 1.6, 3.7, 2.8, 1.5, 1.1, 1.2, 1.4, 2.3, 1.5, 1.2,
    1.7, 1.1, 1.6, 1.2, 1.5, 1.1, 1.2, 1.7, 1.2, 1.6, 1.2, 1.1, 1.8, 1.2, 1.1, 1.0, 1.3, 1.1, 1.6, 1.6,
};
/* estimate_mc.py's docstring array (not the first 36 of MAGNITUDES: one 1.5 fewer). */
static const double DOC36[] = {2.3, 1.2, 1.5, 1.2, 1.7, 1.1, 1.2, 1.8, 1.6, 1.2, 1.5, 1.2,
                               1.7, 1.6, 1.1, 1.1, 1.2, 2.0, 1.1, 1.2, 1.1, 1.2, 1.6, 1.9,
                               1.3, 1.7, 1.3, 1.0, 1.2, 1.7, 1.3, 1.3, 1.1, 1.5, 1.4, 1.5};

static void test_classic(void **state)
{
    (void)state;
    bk_b_estimate est;
    bk_error err = {0};
    assert_int_equal(bk_b_tinti(DOC24, N_OF(DOC24), 2.0, 0.1, &est, &err), BK_OK);
    assert_close(est.b, 1.114920128810535, 1e-14, 0.0); /* classic.py docstring */
    assert_int_equal(est.n, 24);
}

static void test_b_positive(void **state)
{
    (void)state;
    bk_b_positive_estimate bp;
    bk_error err = {0};
    /* positive.py docstring: dmc = 0.2 gives 1.9188552623891313 (10 differences). */
    assert_int_equal(bk_b_positive(DOC24, NULL, N_OF(DOC24), 2.0, 0.1, 0.2, &bp, &err), BK_OK);
    assert_close(bp.fit.b, 1.9188552623891313, 1e-14, 0.0);
    assert_int_equal(bp.fit.n, 10);
    assert_close(bp.fit.sigma, 0.4153418993344462, 1e-12, 0.0); /* SeismoStats' std, run at 4605c4e */
    /* The default dmc = dm: 12 differences. */
    assert_int_equal(bk_b_positive(DOC24, NULL, N_OF(DOC24), 2.0, 0.1, 0.1, &bp, &err), BK_OK);
    assert_close(bp.fit.b, 1.5490195998574319, 1e-14, 0.0);
    assert_int_equal(bp.fit.n, 12);
    /* test_estimate_mc.py: MAGNITUDES at Mc = 1.5: beta = 3.2542240043462796. */
    assert_int_equal(bk_b_positive(MAGNITUDES, NULL, N_OF(MAGNITUDES), 1.5, 0.1, 0.1, &bp, &err), BK_OK);
    assert_close(bp.fit.b * LN_10, 3.2542240043462796, 1e-14, 0.0);
    assert_int_equal(bp.fit.n, 20);
    assert_int_equal(bp.n_events, 45);
    /* test_bvalues.py: the differences follow the times, not the array. */
    const double mags[] = {0.0, 0.9, -1.0, 0.2, 0.5}, shuffled[] = {0.0, 0.9, 0.5, 0.2, -1.0};
    const double days[] = {0, 1, 2, 3, 4}, shuffled_days[] = {0, 1, 4, 3, 2};
    bk_b_positive_estimate a, b;
    assert_int_equal(bk_b_positive(mags, days, 5, -1.0, 0.1, 0.1, &a, &err), BK_OK);
    assert_int_equal(bk_b_positive(shuffled, shuffled_days, 5, -1.0, 0.1, 0.1, &b, &err), BK_OK);
    assert_int_equal(a.fit.n, 3);
    assert_close(a.fit.b, 0.5799194697768674, 1e-14, 0.0);
    assert_true(a.fit.b == b.fit.b);
    /* No positive difference: refused, with the reason. */
    const double falling[] = {5, 4, 3, 2, 1};
    assert_int_equal(bk_b_positive(falling, days, 5, 1.0, 1.0, 1.0, &a, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "0 positive differences"));
}

static void test_a_positive(void **state)
{
    (void)state;
    bk_b_positive_estimate bp;
    bk_error err = {0};
    /* avalue/positive.py docstring: a = 0.9542425094393249 (= log10 9). */
    const double mags[] = {2.1, 2.3, 2.0, 2.0, 2.1, 2.2, 2.1, 2.3, 2.0, 2.0};
    const double t[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
    assert_int_equal(bk_b_positive(mags, t, N_OF(mags), 2.0, 0.1, 0.1, &bp, &err), BK_OK);
    assert_close(bp.a, 0.9542425094393249, 1e-14, 0.0);
    assert_int_equal(bp.fit.n, 4);
    /* test_avalue.py: 10^a = 10 for magnitudes 1..9, 11, 10 on 11 days, Mc = 1, dm = 1. */
    const double steps[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 10};
    const double d[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
    assert_int_equal(bk_b_positive(steps, d, 11, 1.0, 1.0, 1.0, &bp, &err), BK_OK);
    assert_close(pow(10.0, bp.a), 10.0, 1e-13, 0.0);
}

static void test_mc_b_stability(void **state)
{
    (void)state;
    bk_mc_stability st;
    bk_error err = {0};
    /* test_estimate_mc_b_stability_larger_bins: Mc = 1.1 (b 0.9737425087364393, its diff
     * 0.21090553720791072 after 1.0 failed at 1.307). */
    assert_int_equal(bk_mc_b_stability(MAGNITUDES, N_OF(MAGNITUDES), 0.1, 0.5, &st, &err), BK_OK);
    assert_true(st.found);
    assert_close(st.mc, 1.1, 0.0, 1e-12);
    assert_close(st.b, 0.9737425087364393, 1e-13, 0.0);
    assert_close(st.diff, 0.21090553720791072, 1e-12, 0.0);
    assert_int_equal(st.n_tested, 2);
    assert_int_equal(st.steps, 5);
    /* estimate_mc.py's docstring: Mc = 1.1, b 1.190298769977797, diff 0.9457747650207581. */
    assert_int_equal(bk_mc_b_stability(DOC36, N_OF(DOC36), 0.1, 0.5, &st, &err), BK_OK);
    assert_close(st.mc, 1.1, 0.0, 1e-12);
    assert_close(st.b, 1.190298769977797, 1e-13, 0.0);
    assert_close(st.diff, 0.9457747650207581, 1e-12, 0.0);
    /* Too narrow a range of magnitudes for the test. */
    const double narrow[] = {1.0, 1.1, 1.2, 1.1};
    assert_int_equal(bk_mc_b_stability(narrow, 4, 0.1, 0.5, &st, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "the test needs more than 5"));
}

/* b-positive's point: events after a large one are missed for a while, and the classic b
 * drops; b-positive does not (every event it differences against lies above the threshold
 * of the moment).  4e4 GR events (b = 1, M >= 0, bins of 0.1) on a Poisson clock; after
 * every event of M >= 2, for 100 mean interevent times, only events larger than M - 1 are
 * recorded. */
static void test_incompleteness(void **state)
{
    (void)state;
    enum { N = 40000 };
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 21);
    double *m = malloc(N * sizeof *m), *t = malloc(N * sizeof *t);
    assert_true(m && t);
    size_t kept = 0;
    double now = 0.0, blind_until = -1.0, blind_level = 0.0;
    for (size_t i = 0; i < N; ++i) {
        now += gsl_ran_exponential(rng, 1.0);
        double mag = floor((gsl_ran_exponential(rng, log10(exp(1.0))) - 0.05) / 0.1 + 0.5 + 1e-9) * 0.1 + 0.0;
        if (mag < 0.0)
            mag = 0.0;
        if (now < blind_until && mag <= blind_level)
            continue;
        m[kept] = mag;
        t[kept++] = now;
        if (mag >= 2.0) {
            blind_until = now + 100.0;
            blind_level = mag - 1.0;
        }
    }
    bk_error err = {0};
    bk_b_estimate classic;
    bk_b_positive_estimate positive;
    assert_int_equal(bk_b_tinti(m, kept, 0.0, 0.1, &classic, &err), BK_OK);
    assert_int_equal(bk_b_positive(m, t, kept, 0.0, 0.1, 0.1, &positive, &err), BK_OK);
    print_message("%zu events kept of %d: classic b = %.4f +- %.4f, b-positive = %.4f +- %.4f (%zu differences)\n",
                  kept, N, classic.b, classic.sigma, positive.fit.b, positive.fit.sigma, positive.fit.n);
    assert_true(classic.b < 1.0 - 5.0 * classic.sigma);           /* biased low */
    assert_close(positive.fit.b, 1.0, 0.0, 3.0 * positive.fit.sigma); /* recovered */
    free(m);
    free(t);
    gsl_rng_free(rng);
}

/* Mc by the KS method: SeismoStats' distance, and the completeness of a synthetic catalog. */
static void test_mc_ks(void **state)
{
    (void)state;
    bk_error err = {0};
    /* ks_test_gr(MAGNITUDES, mc = 1.0, delta_m = 0.1, b_value = 1): the observed distance,
     * 0.14567176527571873 by SeismoStats 4605c4e (its test then compares it with stored
     * synthetic distances: p = 0.0104). */
    double d = 0.0;
    assert_int_equal(bk_gr_ks_distance(MAGNITUDES, N_OF(MAGNITUDES), 1.0, 0.1, 1.0, &d, &err), BK_OK);
    assert_close(d, 0.14567176527571873, 1e-14, 0.0);
    /* 3000 GR magnitudes (b = 1) complete from 2.0, and below it detected with probability
     * 10^(-3 (1.95 - M)): the KS method finds Mc at the completeness, where maximum curvature
     * + 0.2 sits higher. */
    enum { CAP = 20000 };
    static double m[CAP];
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 2021);
    size_t n = 0, complete = 0;
    while (complete < 3000 && n < CAP) {
        double mag = 1.0 + gsl_ran_exponential(rng, log10(exp(1.0)));
        if (mag < 1.95 && gsl_rng_uniform(rng) >= pow(10.0, -3.0 * (1.95 - mag)))
            continue;
        complete += mag >= 1.95;
        m[n++] = floor(mag / 0.1 + 0.5 + 1e-9) * 0.1;
    }
    bk_mc_ks_result ks;
    assert_int_equal(bk_mc_ks(m, n, 0.1, 0.1, 200, 5, &ks, &err), BK_OK);
    print_message("%zu magnitudes: Mc by KS = %.2f (b = %.4f, D = %.4f, p = %.3f, %zu candidates)\n", n, ks.mc, ks.b,
                  ks.d, ks.p, ks.n_tested);
    assert_true(ks.found);
    assert_true(ks.mc > 1.85 && ks.mc < 2.25);
    assert_close(ks.b, 1.0, 0.0, 0.1);
    /* The same test, seeded: the same answer. */
    bk_mc_ks_result again;
    assert_int_equal(bk_mc_ks(m, n, 0.1, 0.1, 200, 5, &again, &err), BK_OK);
    assert_true(again.mc == ks.mc && again.p == ks.p);
    gsl_rng_free(rng);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_classic),
        cmocka_unit_test(test_b_positive),
        cmocka_unit_test(test_a_positive),
        cmocka_unit_test(test_mc_b_stability),
        cmocka_unit_test(test_incompleteness),
        cmocka_unit_test(test_mc_ks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
