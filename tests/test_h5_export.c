/* The text export (src/output/h5_export.c): default and chosen columns, one block or all,
 * friction-state columns by block, the transitions table, and errors that name what is
 * available. */
#include "bk_test.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "output_fixture.h"
#include "output_files.h"

static char *export_text(const char *path, const char *datasets, long block, int transitions)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_non_null(out);
    bk_error err;
    int rc = bk_h5_export(path, datasets, block, transitions, out, &err);
    fclose(out);
    if (rc != BK_OK)
        fail_msg("export: %s", err.message);
    return text;
}

static void append(char *buf, size_t size, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void append(char *buf, size_t size, const char *fmt, ...)
{
    size_t used = strlen(buf);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + used, size - used, fmt, ap);
    va_end(ap);
}

static void test_export_default_one_block(void **state)
{
    output_fixture *f = *state;
    write_small(f->path, 0);
    char *text = export_text(f->path, NULL, 1, 0);
    char expected[2048] =
        "# time[s] driver[m] x_1[m] v_1[m/s] friction_1[N] cof_1[1] mode_1[1]\n";
    for (int r = 0; r < 3; ++r)
        append(expected, sizeof expected, "%.17g %.17g %.17g %.17g %.17g %.17g %d\n", 0.1 * r,
               0.7 * r, 0.1 * (r + 1) + 1, -0.3 + r, 1.0 / 3.0 + 1, 0.6, 0);
    assert_string_equal(text, expected);
    /* %.17g round-trips: the printed x column parses back to the stored doubles. */
    const char *line = strchr(text, '\n') + 1;
    double t, d, x1;
    assert_int_equal(sscanf(line, "%lf %lf %lf", &t, &d, &x1), 3);
    assert_true(x1 == 0.1 * 1 + 1);
    free(text);
}

static void test_export_all_blocks(void **state)
{
    output_fixture *f = *state;
    write_small(f->path, 1);
    char *text = export_text(f->path, "time, x,mode", -1, 0);
    char expected[2048] = "# time[s] x_0[m] x_1[m] x_2[m] mode_0[1] mode_1[1] mode_2[1]\n";
    for (int r = 0; r < 3; ++r)
        append(expected, sizeof expected, "%.17g %.17g %.17g %.17g %d %d %d\n", 0.1 * r,
               0.1 * (r + 1), 0.1 * (r + 1) + 1, 0.1 * (r + 1) + 2, r ? -1 : 0, 0,
               r ? 1 : 0);
    assert_string_equal(text, expected);
    free(text);

    /* friction_state columns are named block_state and follow the block filter. */
    text = export_text(f->path, "friction_state", 1, 0);
    assert_string_equal(text, "# friction_state_1_0[law-specific] friction_state_1_1[law-specific]\n"
                              "1 2\n11 12\n21 22\n");
    free(text);
    text = export_text(f->path, "friction_state,work_driver", -1, 0);
    assert_non_null(strstr(text, "# friction_state_0_0[law-specific] "
                                 "friction_state_1_0[law-specific] "
                                 "friction_state_1_1[law-specific] "
                                 "friction_state_2_0[law-specific] work_driver[J]\n"
                                 "0 1 2 3 0\n"));
    free(text);
}

static void test_export_transitions(void **state)
{
    output_fixture *f = *state;
    write_small(f->path, 0);
    char header[] = "# t[s] block[1] from[1] to[1] x[m] v[m/s] force[N]\n";
    char all[2048], block0[2048];
    snprintf(all, sizeof all, "%s", header);
    snprintf(block0, sizeof block0, "%s", header);
    for (size_t k = 0; k < 5; ++k) {
        bk_transition t = transition_at(k);
        char line[256];
        snprintf(line, sizeof line, "%.17g %d %d %d %.17g %.17g %.17g\n", t.t, (int)t.block,
                 (int)t.from, (int)t.to, t.x, t.v, t.force);
        append(all, sizeof all, "%s", line);
        if (t.block == 0)
            append(block0, sizeof block0, "%s", line);
    }
    char *text = export_text(f->path, NULL, -1, 1);
    assert_string_equal(text, all);
    free(text);
    text = export_text(f->path, NULL, 0, 1);
    assert_string_equal(text, block0);
    free(text);
}

static void expect_export_error(const char *path, const char *datasets, long block,
                                int transitions, int status, const char *const *needles)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    bk_error err;
    bk_error_clear(&err);
    int rc = bk_h5_export(path, datasets, block, transitions, out, &err);
    fclose(out);
    free(text);
    if (rc != status)
        fail_msg("export returned %d (%s), expected %d", rc, err.message, status);
    for (; *needles; ++needles)
        if (!strstr(err.message, *needles))
            fail_msg("message \"%s\" lacks \"%s\"", err.message, *needles);
}

static void test_export_errors(void **state)
{
    output_fixture *f = *state;
    write_small(f->path, 0);
    expect_export_error(f->path, "time,bogus", -1, 0, BK_ERR_INVALID,
                        (const char *const[]){"no dataset 'bogus'",
                                              "available: time, driver, event, x, v, "
                                              "friction, cof, mode, energy_kinetic",
                                              NULL});
    expect_export_error(f->path, "transitions", -1, 0, BK_ERR_INVALID,
                        (const char *const[]){"no dataset 'transitions'", "available:", NULL});
    expect_export_error(f->path, "time,,x", -1, 0, BK_ERR_INVALID,
                        (const char *const[]){"empty dataset name", NULL});
    expect_export_error(f->path, NULL, 3, 0, BK_ERR_INVALID,
                        (const char *const[]){"block 3 out of range", "3 blocks (allowed: 0..2)", NULL});
    expect_export_error(f->path, NULL, -2, 0, BK_ERR_INVALID,
                        (const char *const[]){"block -2 out of range", "(allowed: 0..2)", NULL});
    expect_export_error(f->path, NULL, 7, 1, BK_ERR_INVALID,
                        (const char *const[]){"(allowed: 0..2)", NULL});

    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
    char other[256];
    snprintf(other, sizeof other, "%s/no_transitions.h5", f->dir);
    write_file(other, c, 3, 0);
    bk_config_free(c);
    expect_export_error(other, NULL, -1, 1, BK_ERR_HDF5,
                        (const char *const[]){other, "no /transitions", NULL});
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        OUTPUT_TEST(test_export_default_one_block),
        OUTPUT_TEST(test_export_all_blocks),
        OUTPUT_TEST(test_export_transitions),
        OUTPUT_TEST(test_export_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
