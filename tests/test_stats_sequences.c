/* Mainshock sequences (src/stats_sequences.c): the selection rules on a hand-made catalog
 * whose every count is known, and the stacked Omori-Utsu fits on seeded synthetic catalogs:
 * aftershocks drawn from K / (t + c)^p after each mainshock (p = 1.1) and foreshocks from the
 * inverse law before it (p = 0.9), over a weak Poisson background.  Levels: the stacked p within 2
 * standard errors of the truth (a calibrated error misses 1 time in 22), the decay found by
 * the likelihood ratio at 1 %, the residual check not rejecting at 5 %; on a catalog without
 * sequences no decay at 1 % either way. */
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

#define SPAN 10000.0
#define WINDOW 200.0
#define N_MAIN 20
#define CAP 200000

static double t_all[CAP], m_all[CAP];

/* n offsets of K / (t + c)^p on [0, WINDOW] by inverting the cumulative rate. */
static size_t omori_offsets(gsl_rng *rng, double k, double c, double p, double *out, size_t cap)
{
    double total = (pow(WINDOW + c, 1.0 - p) - pow(c, 1.0 - p)) / (1.0 - p);
    size_t n = gsl_ran_poisson(rng, k * total);
    if (n > cap)
        n = cap;
    for (size_t i = 0; i < n; ++i) {
        double y = gsl_rng_uniform(rng) * total;
        out[i] = pow(pow(c, 1.0 - p) + (1.0 - p) * y, 1.0 / (1.0 - p)) - c;
    }
    return n;
}

/* Magnitudes of a GR law with b = 1 from 0, below 4: smaller than every mainshock (5). */
static double small_magnitude(gsl_rng *rng)
{
    double m;
    do
        m = -log10(gsl_rng_uniform_pos(rng));
    while (m >= 4.0);
    return m;
}

/* A background at the given rate (1/s), and (with_sequences) N_MAIN mainshocks of magnitude
 * 5 every 500 s from 250 s with their aftershocks and foreshocks. */
static size_t synthetic_catalog(unsigned long seed, double background, int with_sequences)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    size_t n = gsl_ran_poisson(rng, background * SPAN);
    for (size_t i = 0; i < n; ++i) {
        t_all[i] = SPAN * gsl_rng_uniform(rng);
        m_all[i] = small_magnitude(rng);
    }
    for (int j = 0; j < N_MAIN; ++j) {
        double t0 = 250.0 + 500.0 * j;
        t_all[n] = t0;
        m_all[n++] = with_sequences ? 5.0 : small_magnitude(rng) + 1.0;
        if (!with_sequences)
            continue;
        size_t a = omori_offsets(rng, 50.0, 0.05, 1.1, t_all + n, CAP - n);
        for (size_t i = 0; i < a; ++i) {
            t_all[n + i] = t0 + t_all[n + i];
            m_all[n + i] = small_magnitude(rng);
        }
        n += a;
        size_t f = omori_offsets(rng, 10.0, 1.0, 0.9, t_all + n, CAP - n);
        for (size_t i = 0; i < f; ++i) {
            t_all[n + i] = t0 - t_all[n + i];
            m_all[n + i] = small_magnitude(rng);
        }
        n += f;
    }
    gsl_rng_free(rng);
    return n;
}

static void test_stacked_recovers(void **state)
{
    (void)state;
    size_t n = synthetic_catalog(1983, 0.002, 1);
    bk_sequences s;
    bk_error err = {0};
    assert_int_equal(bk_sequences_build(t_all, m_all, n, 0.0, 4.5, WINDOW, 0.0, SPAN, &s, &err), BK_OK);
    assert_int_equal(s.n_candidates, N_MAIN);
    assert_int_equal(s.n_mainshocks, N_MAIN);
    assert_int_equal(s.n_not_largest + s.n_at_edges, 0);
    assert_true(s.after.have_fit && s.before.have_fit);
    const bk_omori *a = &s.after.fit, *b = &s.before.fit;
    print_message("aftershocks: %zu, p = %.4f +- %.4f, c = %.4g +- %.3g, LR %.0f; residual KS p = %.3f\n", s.after.n,
                  a->p, a->p_sigma, a->c, a->c_sigma, a->lr, s.after.residuals.p);
    print_message("foreshocks: %zu, p = %.4f +- %.4f, c = %.4g, LR %.0f; residual KS p = %.3f\n", s.before.n, b->p,
                  b->p_sigma, b->c, b->lr, s.before.residuals.p);
    print_message("single sequences fitted: %zu of %zu\n", s.n_fitted, s.n_mainshocks);
    assert_close(a->p, 1.1, 0.0, 2.0 * a->p_sigma);
    assert_true(a->decays && b->decays);
    /* The background (0.002/s, about 8 events in each stack) is not in the law: it would pull
     * p down where it is a sizeable part of a stack. */
    assert_close(b->p, 0.9, 0.0, 2.0 * b->p_sigma);
    assert_true(s.after.have_residuals && s.after.residuals.p > 0.05);
    assert_true(s.before.have_residuals && s.before.residuals.p > 0.05);
    /* K of the stack is the sum over the mainshocks: about N_MAIN x 50. */
    assert_close(a->k, N_MAIN * 50.0, 0.0, 3.0 * a->k_sigma);
    /* Every sequence holds hundreds of aftershocks: each is fitted alone too. */
    assert_int_equal(s.n_fitted, N_MAIN);
    size_t within = 0;
    for (size_t i = 0; i < s.n_mainshocks; ++i)
        within += fabs(s.sequence[i].fit.p - 1.1) <= 2.0 * s.sequence[i].fit.p_sigma;
    print_message("single p within 2 sigma of 1.1: %zu of %d\n", within, N_MAIN);
    assert_true(within >= N_MAIN - 3);
    bk_sequences_free(&s);
}

static void test_no_sequences(void **state)
{
    (void)state;
    size_t n = synthetic_catalog(7, 0.01, 0);
    bk_sequences s;
    bk_error err = {0};
    /* Mainshocks are the events >= 4: the twenty that are M >= 1 here, and no aftershocks. */
    assert_int_equal(bk_sequences_build(t_all, m_all, n, 0.0, 1.0, WINDOW * 2.0, 0.0, SPAN, &s, &err), BK_OK);
    print_message("%zu mainshocks of %zu candidates; after: %zu events, p = %.3f, LR %.2f; before: %zu, LR %.2f\n",
                  s.n_mainshocks, s.n_candidates, s.after.n, s.after.fit.p, s.after.fit.lr, s.before.n,
                  s.before.fit.lr);
    assert_true(s.n_mainshocks >= 5);
    assert_true(s.after.have_fit && s.before.have_fit);
    assert_false(s.after.fit.decays);
    assert_false(s.before.fit.decays);
    bk_sequences_free(&s);
}

/* Every rule on a catalog small enough to count by hand (window 10 s, span [0, 100] s). */
static void test_selection(void **state)
{
    (void)state;
    const double t[] = {
        5.0,                  /* M 6: its -window leaves the span (at an edge) */
        30.0,                 /* M 5: a mainshock */
        30.0,                 /* M 2 at the same instant: neither before nor after */
        25.0, 28.0,           /* foreshocks of 30 */
        31.0, 32.0, 40.0,     /* aftershocks of 30 (40 is at t + window: in) */
        41.0,                 /* M 1 after the window */
        60.0, 65.0,           /* M 5 and a larger M 5.5 within 10 s: only the later is a mainshock */
        70.0,                 /* M 5 and equal to ... */
        75.0,                 /* ... this M 5: the earlier one takes precedence (60 is not larger:
                                 65's window holds 60, 70, 75) */
        20.0,                 /* M 0.5: below m_min */
    };
    const double m[] = {6.0, 5.0, 2.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 5.0, 5.5, 5.0, 5.0, 0.5};
    size_t n = sizeof t / sizeof t[0];
    bk_sequences s;
    bk_error err = {0};
    assert_int_equal(bk_sequences_build(t, m, n, 1.0, 5.0, 10.0, 0.0, 100.0, &s, &err), BK_OK);
    /* Candidates: 5, 30, 60, 65, 70, 75.  At an edge: 5.  Not the largest: 60 (65), 70 and 75
     * (65 within 10 s of both... 75 is 10 s from 65: in its window). */
    assert_int_equal(s.n_candidates, 6);
    assert_int_equal(s.n_at_edges, 1);
    assert_int_equal(s.n_not_largest, 3);
    assert_int_equal(s.n_mainshocks, 2);
    assert_close(s.sequence[0].t_main, 30.0, 0.0, 0.0);
    assert_int_equal(s.sequence[0].n_after, 3);
    assert_int_equal(s.sequence[0].n_before, 2);
    assert_close(s.sequence[1].t_main, 65.0, 0.0, 0.0);
    /* After 65: 70, 75 (both M 5 >= m_min); before: 60. */
    assert_int_equal(s.sequence[1].n_after, 2);
    assert_int_equal(s.sequence[1].n_before, 1);
    assert_int_equal(s.n_simultaneous, 1);
    assert_int_equal(s.after.n, 5);
    assert_close(s.after.offset[0], 1.0, 0.0, 0.0);
    assert_close(s.after.offset[2], 10.0, 0.0, 0.0);
    assert_false(s.after.have_fit);
    assert_non_null(strstr(s.after.note, "5 aftershocks in all windows: the Omori-Utsu fit needs at least 10"));
    bk_sequences_free(&s);

    /* Two equal magnitudes 5 s apart with nothing larger: the earlier is the mainshock. */
    const double t2[] = {50.0, 55.0}, m2[] = {3.0, 3.0};
    assert_int_equal(bk_sequences_build(t2, m2, 2, 1.0, 3.0, 10.0, 0.0, 100.0, &s, &err), BK_OK);
    assert_int_equal(s.n_mainshocks, 1);
    assert_close(s.sequence[0].t_main, 50.0, 0.0, 0.0);
    assert_int_equal(s.sequence[0].n_after, 1);
    bk_sequences_free(&s);
}

static void test_errors(void **state)
{
    (void)state;
    double t[2] = {1.0, NAN}, m[2] = {1.0, 1.0};
    bk_sequences s;
    bk_error err = {0};
    assert_int_equal(bk_sequences_build(t, m, 2, 0.0, 1.0, 10.0, 0.0, 100.0, &s, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "event 1: t = nan s"));
    assert_int_equal(bk_sequences_build(t, m, 1, 0.0, 1.0, 0.0, 0.0, 100.0, &s, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "sequence window 0 s: allowed > 0"));
    assert_int_equal(bk_sequences_build(t, m, 1, 0.0, 1.0, 10.0, 100.0, 100.0, &s, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "allowed start < end"));
    assert_int_equal(bk_sequences_build(t, m, 1, 0.0, NAN, 10.0, 0.0, 100.0, &s, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "must be finite"));
    /* No event large enough: a result with a reason, not an error. */
    assert_int_equal(bk_sequences_build(t, m, 1, 0.0, 7.0, 10.0, 0.0, 100.0, &s, &err), BK_OK);
    assert_int_equal(s.n_mainshocks, 0);
    assert_string_equal(s.after.note, "no mainshock");
    bk_sequences_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stacked_recovers),
        cmocka_unit_test(test_no_sequences),
        cmocka_unit_test(test_selection),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
