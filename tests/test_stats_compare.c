/* Two catalogs compared (bksim/stats_compare.h, src/stats_compare.c) on catalogs built here in
 * memory: identical ones are the same (D = 0, p = 1), shifted ones and ones drawn from another
 * law are told apart, two draws of one law are not; the events compared are those `bksim
 * stats` counts; rounding keeps a shared potency's last-digit noise from telling two catalogs
 * apart; a catalog without potencies is judged by its magnitudes; bad options and empty
 * catalogs are refused with messages that say why.  The command line is test_cli_compare.c's. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <gsl/gsl_rng.h>

#include "bk_test.h"
#include "bksim/stats.h"
#include "bksim/stats_compare.h"
#include "files.h"

/* Magnitudes as bksim writes them: (2/3) log10 P plus a constant. */
#define MAG_OFFSET 1.0

/* A catalog of n events, one a second from t = 0.5 s, in a run of n seconds: potencies drawn
 * from a power law of density exponent alpha above p_min (seeded), magnitudes from them,
 * n_blocks = ceil(P / p_min), every event complete. */
static bk_event_table power_law_catalog(size_t n, double alpha, double p_min, unsigned long seed)
{
    bk_event_table t;
    memset(&t, 0, sizeof t);
    t.n = n;
    t.t_start = malloc(n * sizeof *t.t_start);
    t.t_end = malloc(n * sizeof *t.t_end);
    t.magnitude = malloc(n * sizeof *t.magnitude);
    t.potency = malloc(n * sizeof *t.potency);
    t.n_blocks = malloc(n * sizeof *t.n_blocks);
    t.complete = malloc(n * sizeof *t.complete);
    assert_true(t.t_start && t.t_end && t.magnitude && t.potency && t.n_blocks && t.complete);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    assert_non_null(rng);
    gsl_rng_set(rng, seed);
    for (size_t i = 0; i < n; ++i) {
        t.t_start[i] = 0.5 + (double)i;
        t.t_end[i] = t.t_start[i] + 0.25;
        t.potency[i] = p_min * pow(gsl_rng_uniform_pos(rng), -1.0 / (alpha - 1.0));
        t.magnitude[i] = 2.0 / 3.0 * log10(t.potency[i]) + MAG_OFFSET;
        double blocks = ceil(t.potency[i] / p_min);
        t.n_blocks[i] = blocks > 1e6 ? 1000000 : (int32_t)blocks;
        t.complete[i] = 1;
    }
    gsl_rng_free(rng);
    t.t_reached = (double)n;
    return t;
}

/* The magnitudes again from the (changed) potencies. */
static void remagnitude(bk_event_table *t)
{
    for (size_t i = 0; i < t->n; ++i)
        t->magnitude[i] = 2.0 / 3.0 * log10(t->potency[i]) + MAG_OFFSET;
}

static void test_identical(void **state)
{
    (void)state;
    bk_event_table a = power_law_catalog(2000, 1.7, 1e-4, 1);
    bk_compare_result r;
    bk_error err = {0};
    assert_int_equal(bk_compare_tables(&a, "a.h5", &a, "a again", NULL, &r, &err), BK_OK);
    const bk_compare_test *tests[] = {&r.log10_potency, &r.magnitude, &r.n_blocks};
    for (size_t k = 0; k < 3; ++k) {
        assert_true(tests[k]->done);
        assert_true(tests[k]->ks.d == 0.0);
        assert_true(tests[k]->ks.p == 1.0);
        assert_false(tests[k]->differ);
        assert_int_equal(tests[k]->ks.n1, 2000);
        assert_int_equal(tests[k]->ks.n2, 2000);
    }
    assert_string_equal(r.primary, "log10_potency");
    assert_false(r.told_apart);
    assert_string_equal(r.a.source, "a.h5");
    assert_string_equal(r.b.source, "a again");
    assert_int_equal(r.a.n_events, 2000);
    assert_int_equal(r.a.n_potency, 2000);
    /* The span is the run's (t_reached = 2000 s): one event a second. */
    assert_true(r.a.duration_from_run);
    assert_close(r.a.duration, 2000.0, 1e-15, 0.0);
    assert_close(r.a.rate, 1.0, 1e-15, 0.0);
    assert_close(r.rate_ratio, 1.0, 1e-15, 0.0);
    /* Defaults: the whole catalog, log10 potency to 1e-4, the 1 % level. */
    assert_true(r.options.t_from == -INFINITY && r.options.t_to == INFINITY);
    assert_close(r.options.round, BK_COMPARE_DEFAULT_ROUND, 0.0, 0.0);
    assert_close(r.options.level, 0.01, 0.0, 0.0);
    bk_compare_free(&r);
    bk_event_table_free(&a);
}

/* Every potency doubled (log10 P + 0.301, magnitudes + 0.2): told apart by all three tests. */
static void test_shifted(void **state)
{
    (void)state;
    bk_event_table a = power_law_catalog(2000, 1.7, 1e-4, 1);
    bk_event_table b = power_law_catalog(2000, 1.7, 1e-4, 1);
    for (size_t i = 0; i < b.n; ++i) {
        b.potency[i] *= 2.0;
        b.n_blocks[i] = (int32_t)ceil(b.potency[i] / 1e-4);
    }
    remagnitude(&b);
    bk_compare_result r;
    bk_error err = {0};
    assert_int_equal(bk_compare_tables(&a, "a.h5", &b, "b.h5", NULL, &r, &err), BK_OK);
    assert_true(r.told_apart);
    assert_true(r.log10_potency.differ && r.magnitude.differ && r.n_blocks.differ);
    /* A power law of exponent 1.7 doubled: F_b(P) = F_a(P / 2), D = 1 - 2^-0.7 = 0.384. */
    assert_close(r.log10_potency.ks.d, 1.0 - pow(2.0, -0.7), 0.0, 0.04);
    assert_true(r.log10_potency.ks.p < 1e-10);
    /* Magnitudes are a monotone map of potencies: the same distance. */
    assert_close(r.magnitude.ks.d, r.log10_potency.ks.d, 0.0, 1e-3);
    bk_compare_free(&r);
    bk_event_table_free(&a);
    bk_event_table_free(&b);
}

/* A changed parameter (the exponent 1.7 -> 1.9, 4000 events each, independent draws) is told
 * apart; two seeds of one law (the no-difference baseline) are not. */
static void test_changed_parameter(void **state)
{
    (void)state;
    bk_event_table a = power_law_catalog(4000, 1.7, 1e-4, 11);
    bk_event_table same = power_law_catalog(4000, 1.7, 1e-4, 12);
    bk_event_table other = power_law_catalog(4000, 1.9, 1e-4, 13);
    bk_compare_result r;
    bk_error err = {0};
    assert_int_equal(bk_compare_tables(&a, "alpha 1.7", &same, "alpha 1.7, seed 12", NULL, &r, &err), BK_OK);
    print_message("two seeds: D = %.4f, p = %.3g\n", r.log10_potency.ks.d, r.log10_potency.ks.p);
    assert_false(r.told_apart);
    assert_true(r.log10_potency.ks.p >= 0.01);
    bk_compare_free(&r);
    assert_int_equal(bk_compare_tables(&a, "alpha 1.7", &other, "alpha 1.9", NULL, &r, &err), BK_OK);
    print_message("alpha 1.7 vs 1.9: D = %.4f, p = %.3g\n", r.log10_potency.ks.d, r.log10_potency.ks.p);
    assert_true(r.told_apart);
    assert_true(r.log10_potency.ks.p < 0.01);
    /* The stricter level 1e-6 still tells them apart; p is the same, the verdict the level's. */
    double p = r.log10_potency.ks.p;
    bk_compare_free(&r);
    bk_compare_options opt;
    bk_compare_options_default(&opt);
    opt.level = p * 0.5;
    assert_int_equal(bk_compare_tables(&a, "alpha 1.7", &other, "alpha 1.9", &opt, &r, &err), BK_OK);
    assert_false(r.told_apart);
    assert_close(r.log10_potency.ks.p, p, 0.0, 0.0);
    bk_compare_free(&r);
    bk_event_table_free(&a);
    bk_event_table_free(&same);
    bk_event_table_free(&other);
}

/* A chain's catalog: 80 % one-block ruptures sharing one potency up to the integrator's last
 * digits, the rest a power law.  A holds the shared value with a relative noise of 1e-9, B
 * exactly: as stored, the atom alone tells them apart (D = 0.8: every copy in A lies above
 * every copy in B); rounded to 1e-4 in log10 they are one value again and D = 0. */
static void test_rounding_ties(void **state)
{
    (void)state;
    bk_event_table a = power_law_catalog(5000, 1.7, 1e-3, 5);
    bk_event_table b = power_law_catalog(5000, 1.7, 1e-3, 5);
    const double atom = 1.5198510572347619e-4; /* carlson_langer_100.ini's one-block potency */
    for (size_t i = 0; i < a.n; ++i)
        if (i % 5 != 0) {
            a.potency[i] = atom * (1.0 + 1e-9 * (double)(1 + i % 7));
            b.potency[i] = atom;
            a.n_blocks[i] = b.n_blocks[i] = 1;
        }
    remagnitude(&a);
    remagnitude(&b);
    bk_compare_options opt;
    bk_compare_options_default(&opt);
    opt.round = 0.0;
    bk_compare_result r;
    bk_error err = {0};
    assert_int_equal(bk_compare_tables(&a, "a", &b, "b", &opt, &r, &err), BK_OK);
    assert_close(r.log10_potency.ks.d, 0.8, 0.0, 1e-12);
    assert_true(r.told_apart);
    /* The block counts hold no such noise: the same either way. */
    assert_true(r.n_blocks.ks.d == 0.0);
    bk_compare_free(&r);
    assert_int_equal(bk_compare_tables(&a, "a", &b, "b", NULL, &r, &err), BK_OK);
    assert_true(r.log10_potency.ks.d == 0.0);
    assert_true(r.magnitude.ks.d == 0.0);
    assert_false(r.told_apart);
    /* Rounded, the median of the log10 potencies is the atom's bin. */
    assert_close(r.a.log10_potency_median, -3.8182, 0.0, 1e-9);
    bk_compare_free(&r);
    bk_event_table_free(&a);
    bk_event_table_free(&b);
}

/* The events compared are those `bksim stats` counts: complete, finite start and magnitude,
 * starting in [t_from, t_to); zero potencies stay out of the potency test only; the span is
 * the run's clipped to the window, or the catalog's own without t_reached. */
static void test_selection(void **state)
{
    (void)state;
    bk_event_table a = power_law_catalog(100, 1.7, 1e-4, 3);
    a.complete[0] = 0;           /* t = 0.5: still running at the end */
    a.magnitude[1] = NAN;        /* t = 1.5 */
    a.potency[2] = 0.0;          /* t = 2.5: zero potency, magnitude -inf */
    a.magnitude[2] = -INFINITY;
    a.potency[3] = 0.0;          /* t = 3.5: zero potency, a finite magnitude (another program's) */
    bk_compare_options opt;
    bk_compare_options_default(&opt);
    opt.t_from = 10.0;           /* events 0..9 start before */
    opt.t_to = 90.0;             /* events 90..99 start at or after */
    bk_compare_result r;
    bk_error err = {0};
    assert_int_equal(bk_compare_tables(&a, "a", &a, "a", &opt, &r, &err), BK_OK);
    assert_int_equal(r.a.n_rows, 100);
    assert_int_equal(r.a.n_incomplete, 1);
    assert_int_equal(r.a.n_nonfinite, 2);
    assert_int_equal(r.a.n_outside, 17);
    assert_int_equal(r.a.n_events, 80);
    assert_int_equal(r.a.n_potency, 80);
    assert_close(r.a.duration, 80.0, 1e-15, 0.0);
    assert_close(r.a.rate, 1.0, 1e-15, 0.0);
    assert_int_equal(r.log10_potency.ks.n1, 80);
    bk_compare_free(&r);
    /* The whole catalog: the zero potency with a finite magnitude is an event, not a potency. */
    assert_int_equal(bk_compare_tables(&a, "a", &a, "a", NULL, &r, &err), BK_OK);
    assert_int_equal(r.a.n_events, 97);
    assert_int_equal(r.a.n_potency, 96);
    assert_int_equal(r.magnitude.ks.n1, 97);
    assert_int_equal(r.log10_potency.ks.n1, 96);
    bk_compare_free(&r);
    /* Without t_reached: from the first start (3.5 s) to the last end (99.75 s). */
    a.t_reached = NAN;
    assert_int_equal(bk_compare_tables(&a, "a", &a, "a", NULL, &r, &err), BK_OK);
    assert_false(r.a.duration_from_run);
    assert_close(r.a.duration, 99.75 - 3.5, 1e-14, 0.0);
    bk_compare_free(&r);
    bk_event_table_free(&a);
}

/* A catalog of t_start and magnitude only (another program's): the magnitude test is the
 * verdict's, the other two say why they were not made. */
static void test_magnitudes_only(void **state)
{
    (void)state;
    bk_event_table a = power_law_catalog(500, 1.7, 1e-4, 21);
    bk_event_table b = power_law_catalog(500, 1.7, 1e-4, 21);
    free(a.potency);
    free(a.n_blocks);
    free(a.complete);
    a.potency = NULL;
    a.n_blocks = NULL;
    a.complete = NULL;
    bk_compare_result r;
    bk_error err = {0};
    assert_int_equal(bk_compare_tables(&a, "other.h5", &b, "b.h5", NULL, &r, &err), BK_OK);
    assert_string_equal(r.primary, "magnitude");
    assert_false(r.log10_potency.done);
    assert_non_null(strstr(r.log10_potency.note, "no potency field in A"));
    assert_false(r.n_blocks.done);
    assert_non_null(strstr(r.n_blocks.note, "no n_blocks field in A"));
    assert_true(r.magnitude.done);
    assert_true(r.magnitude.ks.d == 0.0);
    assert_false(r.told_apart);
    FILE *f = tmpfile();
    assert_non_null(f);
    assert_int_equal(bk_compare_text(&r, f, &err), BK_OK);
    char *text = written_text(f);
    assert_non_null(strstr(text, "log10 potency  not tested: potency: no potency field in A"));
    assert_non_null(strstr(text, "verdict: not told apart at the 1 % level (magnitude: p = 1 >= 0.01)"));
    free(text);
    fclose(f);
    bk_compare_free(&r);
    /* Potencies all zero in B (magnitudes of another scale): no potency to test either. */
    for (size_t i = 0; i < b.n; ++i)
        b.potency[i] = 0.0;
    assert_int_equal(bk_compare_tables(&b, "b.h5", &b, "b.h5", NULL, &r, &err), BK_OK);
    assert_false(r.log10_potency.done);
    assert_non_null(strstr(r.log10_potency.note, "no positive, finite value in either catalog"));
    assert_string_equal(r.primary, "magnitude");
    assert_true(r.n_blocks.done);
    bk_compare_free(&r);
    bk_event_table_free(&a);
    bk_event_table_free(&b);
}

/* The text and the JSON: counts, the three tests, the verdict at the level given. */
static void test_text_and_json(void **state)
{
    (void)state;
    bk_event_table a = power_law_catalog(1000, 1.7, 1e-4, 1);
    bk_event_table b = power_law_catalog(1000, 1.7, 1e-4, 1);
    for (size_t i = 0; i < b.n; ++i)
        b.potency[i] *= 3.0;
    remagnitude(&b);
    b.complete[7] = 0;
    bk_compare_options opt;
    bk_compare_options_default(&opt);
    opt.level = 0.05;
    opt.t_from = 100.0;
    bk_compare_result r;
    bk_error err = {0};
    assert_int_equal(bk_compare_tables(&a, "a.h5", &b, "b.h5", &opt, &r, &err), BK_OK);
    FILE *f = tmpfile();
    assert_non_null(f);
    assert_int_equal(bk_compare_text(&r, f, &err), BK_OK);
    char *text = written_text(f);
    fclose(f);
    assert_non_null(strstr(text, "A: a.h5, columns in memory: 1000 rows\n  left out: 100 outside the time window\n"));
    assert_non_null(strstr(text, "  left out: 1 still running at the end (complete = 0), 99 outside the time window\n"));
    assert_non_null(strstr(text, "time window: events starting at t >= 100 s\n"));
    assert_non_null(strstr(text, "rounded to multiples of 0.0001"));
    assert_non_null(strstr(text, "  n_blocks       D = "));
    assert_non_null(strstr(text, "verdict: told apart at the 5 % level (log10 potency: p = "));
    free(text);
    f = tmpfile();
    assert_non_null(f);
    assert_int_equal(bk_compare_json(&r, f, &err), BK_OK);
    text = written_text(f);
    fclose(f);
    assert_non_null(strstr(text, "\"n_events\": 900, "));
    assert_non_null(strstr(text, "\"n_incomplete\": 1, "));
    assert_non_null(strstr(text, "\"options\": {\"t_from\": 100, \"t_to\": null, \"round\": 0.0001, \"level\": 0.05}"));
    assert_non_null(strstr(text, "\"differ\": true}"));
    assert_non_null(strstr(text, "\"verdict\": {\"test\": \"log10_potency\", \"told_apart\": true, \"level\": 0.05}}\n"));
    free(text);
    bk_compare_free(&r);
    bk_event_table_free(&a);
    bk_event_table_free(&b);
}

static void expect_error(const bk_event_table *a, const bk_event_table *b, const bk_compare_options *opt,
                         const char *needle)
{
    bk_compare_result r;
    bk_error err = {0};
    assert_int_equal(bk_compare_tables(a, "a.h5", b, "b.h5", opt, &r, &err), BK_ERR_INVALID);
    if (!strstr(err.message, needle))
        print_error("message \"%s\" lacks \"%s\"\n", err.message, needle);
    assert_non_null(strstr(err.message, needle));
    /* Nothing is left allocated, and freeing again is harmless. */
    assert_null(r.a.source);
    bk_compare_free(&r);
}

static void test_errors(void **state)
{
    (void)state;
    bk_event_table a = power_law_catalog(50, 1.7, 1e-4, 1);
    bk_compare_options opt;
    bk_compare_options_default(&opt);
    bk_error err = {0};
    assert_int_equal(bk_compare_options_check(&opt, &err), BK_OK);
    opt.level = 0.0;
    expect_error(&a, &a, &opt, "level 0: allowed 0 < level < 1");
    opt.level = 1.0;
    expect_error(&a, &a, &opt, "level 1: allowed 0 < level < 1");
    opt.level = NAN;
    expect_error(&a, &a, &opt, "level nan");
    bk_compare_options_default(&opt);
    opt.round = -1e-4;
    expect_error(&a, &a, &opt, "rounding -0.0001: allowed 0 <= round <= 1");
    opt.round = 2.0;
    expect_error(&a, &a, &opt, "rounding 2");
    bk_compare_options_default(&opt);
    opt.t_from = 30.0;
    opt.t_to = 10.0;
    expect_error(&a, &a, &opt, "time window [30, 10) s: allowed from < to");
    /* No event in the window: the message names the catalog and counts what was left out. */
    opt.t_from = 1000.0;
    opt.t_to = 2000.0;
    expect_error(&a, &a, &opt, "a.h5: no event to compare: of 50 rows, 0 still running at the end "
                               "(complete = 0), 0 without a finite t_start and magnitude, 50 outside the time window");
    /* B every row still running: B named, A's allocations released. */
    bk_event_table b = power_law_catalog(20, 1.7, 1e-4, 2);
    for (size_t i = 0; i < b.n; ++i)
        b.complete[i] = 0;
    expect_error(&a, &b, NULL, "b.h5: no event to compare: of 20 rows, 20 still running");
    /* An empty table. */
    bk_event_table empty;
    memset(&empty, 0, sizeof empty);
    empty.t_reached = NAN;
    expect_error(&empty, &a, NULL, "a.h5: no event to compare: of 0 rows");
    bk_event_table_free(&a);
    bk_event_table_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_identical),     cmocka_unit_test(test_shifted),
        cmocka_unit_test(test_changed_parameter), cmocka_unit_test(test_rounding_ties),
        cmocka_unit_test(test_selection),     cmocka_unit_test(test_magnitudes_only),
        cmocka_unit_test(test_text_and_json), cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests_name("stats_compare", tests, NULL, NULL);
}
