/* `bksim info` (src/output/h5_info.c): the summary of a complete file: parameters, config,
 * phases per block, transitions, statistics to 9 digits, and the integrity verdict. */
#include "bk_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bksim/bksim.h"
#include "output_fixture.h"
#include "output_files.h"

/* bk_h5_info's text for path, which must return status and contain every needle;
 * malloc'ed. */
static char *expect_info(const char *path, int status, const char *const *needles, size_t n)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_non_null(out);
    bk_error err;
    assert_int_equal(bk_h5_info(path, out, &err), status);
    fclose(out);
    for (size_t i = 0; i < n; ++i)
        if (!strstr(text, needles[i]))
            fail_msg("info output lacks \"%s\":\n%s", needles[i], text);
    return text;
}

static void test_info(void **state)
{
    output_fixture *f = *state;
    write_small(f->path, 0);
    static const char *const needles[] = {
        "config name  tests/run.ini\n",
        "version      " BKSIM_VERSION "\n",
        "host         ", /* where the run was made, and its seed: a point can be rerun */
        "seed         0\n",
        "complete     1\n",
        "t_end        0.2 s\n",
        "t_reached    0.2 s\n",
        "n_blocks     3\n",
        "rows         3\n",
        "config:\n    [run]\n    t_end = 10\n    \n    [chain]\n    blocks = 3\nphases",
        /* Row 0 all stick; transitions to: block 0 slip+, stick, slip-; block 1 slip+;
         * block 2 slip-. */
        "    block 0: 2 stick, 2 slip\n",
        "    block 1: 1 stick, 1 slip\n",
        "    block 2: 1 stick, 1 slip\n",
        "transitions  5\n",
        "stats:\n    method             cvode_adams\n    steps              1234\n",
        "    wall_time          0.5 s\n",
        "    work_driver        2.5 J\n",
        "    energy_residual    1e-12\n",
    };
    char *text = expect_info(f->path, BK_OK, needles, sizeof needles / sizeof *needles);
    /* Times and statistics are printed for reading, to 9 significant digits. */
    double t_reached = NAN, residual = NAN;
    assert_int_equal(sscanf(strstr(text, "t_reached "), "t_reached %lf", &t_reached), 1);
    assert_int_equal(sscanf(strstr(text, "energy_residual "), "energy_residual %lf", &residual), 1);
    assert_close(t_reached, 0.1 * 2, 1e-9, 0.0);
    assert_close(residual, 1e-12, 1e-9, 0.0);
    free(text);
}

/* A run without /mode and /transitions still gets its summary: phases cannot be counted
 * (zero) and transitions are "not recorded". */
static void test_info_without_transitions(void **state)
{
    output_fixture *f = *state;
    bk_config *c = synthetic_config(2, BK_FIELD_X, 0, 0);
    c->t_end = row_time(4);
    write_file(f->path, c, 5, 0);
    bk_config_free(c);
    static const char *const needles[] = {
        "n_blocks     2\n", "rows         5\n", "    block 0: 0 stick, 0 slip\n",
        "    block 1: 0 stick, 0 slip\n", "transitions  not recorded\n", "integrity    ok\n",
    };
    free(expect_info(f->path, BK_OK, needles, sizeof needles / sizeof *needles));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        OUTPUT_TEST(test_info),
        OUTPUT_TEST(test_info_without_transitions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
