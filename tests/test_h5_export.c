/* The text export (src/output/h5_export.c): default and chosen columns, one block or all,
 * friction-state columns by block, the transitions table, the /events catalog as TSV, and
 * errors that name what is available or missing. */
#include "bk_test.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <hdf5.h>

#include "bksim/bksim.h"
#include "command.h"
#include "h5_raw.h"
#include "layout.h"
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
        "# time[s] event[1] driver[m] x_1[m] v_1[m/s] friction_1[N] cof_1[1] mode_1[1]\n";
    for (int r = 0; r < 3; ++r)
        append(expected, sizeof expected, "%.17g %d %.17g %.17g %.17g %.17g %.17g %d\n", 0.1 * r, 0,
               0.7 * r, 0.1 * (r + 1) + 1, -0.3 + r, 1.0 / 3.0 + 1, 0.6, 0);
    assert_string_equal(text, expected);
    /* %.17g round-trips: the printed x column parses back to the stored doubles. */
    const char *line = strchr(text, '\n') + 1;
    double t, e, d, x1;
    assert_int_equal(sscanf(line, "%lf %lf %lf %lf", &t, &e, &d, &x1), 4);
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

/* ------------------------------------------------------------------ /events --- */

static const char EVENTS_HEADER[] =
    "# t_start[s]\tt_end[s]\tfirst_block[1]\tn_blocks[1]\tleft[1]\tright[1]\tn_episodes[1]\t"
    "potency[m]\tmagnitude[1]\tmax_slip_rate[m/s]\tstress_drop[N]\tcomplete[1]\n";

static char *export_events_text(const char *path)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_non_null(out);
    bk_error err;
    int rc = bk_h5_export_events(path, out, &err);
    fclose(out);
    if (rc != BK_OK)
        fail_msg("export --events: %s", err.message);
    return text;
}

/* Event k of a synthetic catalog on 3 blocks: non-round doubles, a wrapping extent
 * (left > right) every 5th, zero potency (magnitude -inf) every 7th, the last still
 * running. */
static bk_event event_at(size_t k, size_t count)
{
    double t = 1e-4 * (double)k + 1.0 / 3.0;
    int wrap = k % 5 == 4, zero = k % 7 == 6;
    bk_event e = {.t_start = t, .t_end = t + 0.7e-4 / 3.0,
                  .first_block = (int32_t)(k % 3), .n_blocks = wrap ? 2 : 1,
                  .left = wrap ? 2 : (int32_t)(k % 3), .right = wrap ? 0 : (int32_t)(k % 3),
                  .n_episodes = (int32_t)(1 + k % 4),
                  .potency = zero ? 0.0 : 1e-5 * (1.0 + 1.0 / (double)(k + 3)),
                  .max_slip_rate = 0.1 / 7.0 * (double)(k + 1), .stress_drop = -0.2 + 1.0 / 9.0,
                  .complete = k + 1 < count};
    e.magnitude = zero ? -INFINITY : 2.0 / 3.0 * log10(e.potency);
    return e;
}

/* Parse one exported row; returns the number of fields read (12 for a whole row). */
static int parse_event_row(const char *line, bk_event *e, const char **next)
{
    char *end;
    double d[12];
    int n = 0;
    const char *p = line;
    for (; n < 12; ++n) {
        d[n] = strtod(p, &end);
        if (end == p)
            break;
        p = end;
        if (*p != (n < 11 ? '\t' : '\n'))
            break;
        ++p;
    }
    *next = p;
    *e = (bk_event){.t_start = d[0], .t_end = d[1], .first_block = (int32_t)d[2],
                    .n_blocks = (int32_t)d[3], .left = (int32_t)d[4], .right = (int32_t)d[5],
                    .n_episodes = (int32_t)d[6], .potency = d[7], .magnitude = d[8],
                    .max_slip_rate = d[9], .stress_drop = d[10], .complete = (int8_t)d[11]};
    return n;
}

static void expect_same_event(const bk_event *got, const bk_event *want, size_t row)
{
    /* %.17g round-trips every double, -inf included. */
    if (got->t_start != want->t_start || got->t_end != want->t_end ||
        got->first_block != want->first_block || got->n_blocks != want->n_blocks ||
        got->left != want->left || got->right != want->right ||
        got->n_episodes != want->n_episodes || got->potency != want->potency ||
        got->magnitude != want->magnitude || got->max_slip_rate != want->max_slip_rate ||
        got->stress_drop != want->stress_drop || got->complete != want->complete)
        fail_msg("row %zu: got t_start %.17g magnitude %.17g left %d right %d complete %d, "
                 "expected %.17g %.17g %d %d %d", row, got->t_start, got->magnitude,
                 (int)got->left, (int)got->right, (int)got->complete, want->t_start,
                 want->magnitude, (int)want->left, (int)want->right, (int)want->complete);
}

/* Every row of text (after the header) equals the events, in order. */
static void expect_events_text(const char *text, const bk_event *events, size_t count)
{
    assert_true(strncmp(text, EVENTS_HEADER, strlen(EVENTS_HEADER)) == 0);
    const char *p = text + strlen(EVENTS_HEADER);
    size_t rows = 0;
    while (*p) {
        bk_event e;
        const char *next;
        if (parse_event_row(p, &e, &next) != 12)
            fail_msg("row %zu is not 12 tab-separated fields: \"%.80s\"", rows, p);
        if (rows >= count)
            fail_msg("more rows than the %zu events", count);
        expect_same_event(&e, &events[rows], rows);
        ++rows;
        p = next;
    }
    assert_int_equal(rows, count);
}

/* More events than one read buffer (EVENT_BUFFER = 256), so the rows come in three reads;
 * values, wrapping extents, -inf magnitudes and the open last event round-trip. */
static void test_export_events_round_trip(void **state)
{
    output_fixture *f = *state;
    enum { COUNT = 600 };
    bk_event *events = malloc(COUNT * sizeof *events);
    assert_non_null(events);
    for (size_t k = 0; k < COUNT; ++k)
        events[k] = event_at(k, COUNT);
    write_small_with_events(f->path, NULL, 0, events, COUNT);
    char *text = export_events_text(f->path);
    expect_events_text(text, events, COUNT);
    /* The row of a wrapping, zero-potency event, as text. */
    char line[512];
    bk_event e = events[34]; /* 34 % 5 == 4, 34 % 7 == 6 */
    snprintf(line, sizeof line, "\n%.17g\t%.17g\t1\t2\t2\t0\t3\t0\t-inf\t%.17g\t%.17g\t1\n",
             e.t_start, e.t_end, e.max_slip_rate, e.stress_drop);
    assert_non_null(strstr(text, line));
    /* The last row: the event still running. */
    size_t len = strlen(text);
    assert_true(len > 3 && strcmp(text + len - 3, "\t0\n") == 0);
    free(text);

    /* An empty catalog: the header alone. */
    write_small_with_events(f->path, NULL, 0, events, 0);
    text = export_events_text(f->path);
    assert_string_equal(text, EVENTS_HEADER);
    free(text);
    free(events);
}

/* A real run's catalog (case A, a single block under Coulomb friction): the export equals
 * what bk_h5_read_events reads, and `bksim export --events` prints the same text. */
static void test_export_events_real_run(void **state)
{
    output_fixture *f = *state;
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -o %s --quiet",
             f->path);
    char *output = NULL;
    int status = run_command(cmd, &output);
    if (status != 0)
        fail_msg("%s: status %d: %s", cmd, status, output);
    free(output);
    bk_event *events = NULL;
    size_t count = 0;
    bk_error err;
    assert_int_equal(bk_h5_read_events(f->path, &events, &count, &err), BK_OK);
    assert_true(count >= 2);
    char *text = export_events_text(f->path);
    expect_events_text(text, events, count);

    snprintf(cmd, sizeof cmd, "./bksim export %s --events", f->path);
    assert_int_equal(run_command(cmd, &output), 0);
    assert_string_equal(output, text);
    free(output);
    free(text);
    free(events);

    /* Options that do not go with --events are usage errors (exit status 2). */
    const char *extra[] = {"--block 0", "--transitions", "--datasets time"};
    for (size_t k = 0; k < sizeof extra / sizeof extra[0]; ++k) {
        snprintf(cmd, sizeof cmd, "./bksim export %s --events %s", f->path, extra[k]);
        assert_int_equal(run_command(cmd, &output), 2);
        assert_non_null(strstr(output, "--events"));
        free(output);
    }
}

static void expect_events_error(const char *path, int status, const char *needle)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    bk_error err;
    bk_error_clear(&err);
    int rc = bk_h5_export_events(path, out, &err);
    fclose(out);
    free(text);
    if (rc != status)
        fail_msg("export --events returned %d (%s), expected %d", rc, err.message, status);
    if (!strstr(err.message, path) || !strstr(err.message, needle))
        fail_msg("message \"%s\" lacks \"%s\" or \"%s\"", err.message, path, needle);
}

static void test_export_events_errors(void **state)
{
    output_fixture *f = *state;
    /* No /events: a run written with [output] events = false. */
    write_small(f->path, 0);
    expect_events_error(f->path, BK_ERR_INVALID, "no /events table");
    char cmd[512];
    snprintf(cmd, sizeof cmd, "./bksim export %s --events", f->path);
    char *output = NULL;
    assert_int_equal(run_command(cmd, &output), 1);
    assert_non_null(strstr(output, f->path));
    assert_non_null(strstr(output, "/events"));
    free(output);

    /* A catalog from elsewhere, with only t_start and magnitude: not bksim's fields. */
    char other[256];
    snprintf(other, sizeof other, "%s/foreign.h5", f->dir);
    hid_t file = H5Fcreate(other, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hid_t type = H5Tcreate(H5T_COMPOUND, 2 * sizeof(double));
    H5Tinsert(type, "t_start", 0, H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "magnitude", sizeof(double), H5T_NATIVE_DOUBLE);
    hsize_t dims[1] = {2};
    hid_t space = H5Screate_simple(1, dims, NULL);
    hid_t dset = H5Dcreate2(file, "events", type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const double rows[] = {1.0, 2.0, 3.0, 4.0};
    assert_true(H5Dwrite(dset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) >= 0);
    H5Dclose(dset);
    H5Sclose(space);
    H5Tclose(type);
    H5Fclose(file);
    expect_events_error(other, BK_ERR_INVALID, "/events has no field 't_end'");

    /* Missing file; damaged rows. */
    snprintf(other, sizeof other, "%s/missing.h5", f->dir);
    expect_events_error(other, BK_ERR_IO, "");
    bk_event ok[2] = {event_at(0, 2), event_at(1, 2)};
    write_small_with_events(f->path, NULL, 0, ok, 2);
    clobber_chunk(f->path, "events", 0, BK_EVENT_RECORD_BYTES);
    expect_events_error(f->path, BK_ERR_DAMAGED, "/events rows 0..1 cannot be read");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        OUTPUT_TEST(test_export_default_one_block),
        OUTPUT_TEST(test_export_all_blocks),
        OUTPUT_TEST(test_export_transitions),
        OUTPUT_TEST(test_export_errors),
        OUTPUT_TEST(test_export_events_round_trip),
        OUTPUT_TEST(test_export_events_real_run),
        OUTPUT_TEST(test_export_events_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
