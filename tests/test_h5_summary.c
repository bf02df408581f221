/* bk_h5_summary (`bksim summary DIR`): the figures of each run against the single block's
 * closed form, the columns of the TSV and of the HDF5 table, and what is left out; the
 * catalog table behind the figures (/ruptures, else /events, or the one named) against the
 * tables of a ring's run.  Runs ./bksim from the repository root to make the outputs. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <hdf5.h>

#include "bk_test.h"
#include "bksim/bksim.h"
#include "command.h"
#include "files.h"
#include "h5_raw.h"

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    return make_temp_dir(tmpdir, sizeof tmpdir, "bksim_summary");
}

static int teardown(void **state)
{
    (void)state;
    return remove_tree(tmpdir);
}

/* Case A's block (m = 1 kg, k = 1e4 N/m, N = 9.81 N, mu_s = 0.6, V = 1 mm/s) under Coulomb
 * friction: a stick of 2 (mu_s - mu_d) N / (k V), then a slip of (2 pi - 2 atan(A w / V)) / w
 * with A = (mu_s - mu_d) N / k, w = sqrt(k / m), whose fastest speed is V + sqrt((A w)^2 + V^2). */
static void closed_form(double mu_d, double *period, double *peak)
{
    const double k = 1e4, n = 9.81, v = 1e-3, w = 100.0, a = (0.6 - mu_d) * n / k;
    *period = 2.0 * (0.6 - mu_d) * n / (k * v) + (4.0 * acos(0.0) - 2.0 * atan(a * w / v)) / w;
    *peak = v + sqrt(a * w * a * w + v * v);
}

/* The whitespace-free field `column` (0-based) of the line of `path` that starts with
 * `first`, tab-separated; static buffer. */
static const char *tsv_field(const char *path, const char *first, int column)
{
    static char line[8192];
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    const char *found = NULL;
    while (!found && fgets(line, sizeof line, f))
        if (strncmp(line, first, strlen(first)) == 0 && line[strlen(first)] == '\t')
            found = line;
    fclose(f);
    assert_non_null(found);
    char *save = NULL, *field = strtok_r(line, "\t\n", &save);
    for (int c = 0; c < column && field; ++c)
        field = strtok_r(NULL, "\t\n", &save);
    assert_non_null(field);
    return field;
}

static int header_column(const char *path, const char *name)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[8192];
    int column = -1;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "file\t", 5) == 0) {
            char *save = NULL;
            int c = 0;
            for (char *field = strtok_r(line, "\t\n", &save); field; field = strtok_r(NULL, "\t\n", &save), ++c)
                if (strcmp(field, name) == 0)
                    column = c;
        }
    fclose(f);
    return column;
}

static double tsv_number(const char *path, const char *file, const char *name)
{
    int column = header_column(path, name);
    assert_true(column >= 0);
    return strtod(tsv_field(path, file, column), NULL);
}

static void test_figures_and_columns(void **state)
{
    (void)state;
    char dir[300], cmd[4096];
    snprintf(dir, sizeof dir, "%s/runs", tmpdir);
    const double mu_d[2] = {0.1, 0.3};
    for (int k = 0; k < 2; ++k) {
        snprintf(cmd, sizeof cmd,
                 "./bksim run configs/paper/case_a_coulomb.ini -q -o %s/mu_%d.h5 --point p%d "
                 "--set friction.mu_d=%g --set run.t_end=8%s",
                 dir, k, k, mu_d[k], k ? " --set solver.method=exact" : "");
        assert_int_equal(run_command(cmd, NULL), 0);
    }
    /* Without a catalog: the peak slip rate from /v, sampled every 0.1 ms. */
    snprintf(cmd, sizeof cmd,
             "./bksim run configs/paper/case_a_coulomb.ini -q -o %s/mu_2.h5 --set friction.mu_d=0.1 "
             "--set run.t_end=8 --set output.events=false", dir);
    assert_int_equal(run_command(cmd, NULL), 0);
    /* Left out: a run that did not finish, an HDF5 file of another program, not HDF5 at all. */
    snprintf(cmd, sizeof cmd,
             "./bksim run configs/paper/case_a_coulomb.ini -q -o %s/stopped.h5 --set run.t_end=1e4 "
             "--set output.interval=0 --set run.wall_time_limit=0.01; "
             "cp %s/mu_0.h5 %s/other.h5 && h5ls %s/other.h5 > /dev/null && echo text > %s/text.h5",
             dir, dir, dir, dir, dir);
    run_command(cmd, NULL);
    char other_path[600];
    snprintf(other_path, sizeof other_path, "%s/other.h5", dir);
    hid_t other = H5Fopen(other_path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(other >= 0);
    assert_true(H5Adelete(other, "version") >= 0);
    H5Fclose(other);

    char notes_path[600];
    snprintf(notes_path, sizeof notes_path, "%s/notes.txt", tmpdir);
    FILE *notes = fopen(notes_path, "w");
    assert_non_null(notes);
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    bk_error err = {0};
    size_t runs = 0;
    int rc = bk_h5_summary(dir, NULL, &opt, notes, &runs, &err);
    fclose(notes);
    if (rc != BK_OK)
        print_message("%s\n", err.message);
    assert_int_equal(rc, BK_OK);
    assert_int_equal(runs, 3);
    char *text = NULL;
    snprintf(cmd, sizeof cmd, "cat %s", notes_path);
    run_command(cmd, &text);
    assert_non_null(strstr(text, "other.h5: not a bksim output"));
    assert_non_null(strstr(text, "text.h5: not an HDF5 file"));
    assert_null(strstr(text, "stopped")); /* stopped.h5.part is no *.h5 */
    free(text);

    char tsv[600];
    snprintf(tsv, sizeof tsv, "%s/summary.tsv", dir);
    for (int k = 0; k < 2; ++k) {
        char file[32];
        snprintf(file, sizeof file, "mu_%d.h5", k);
        double period, peak;
        closed_form(mu_d[k], &period, &peak);
        assert_close(tsv_number(tsv, file, "friction.mu_d"), mu_d[k], 0.0, 0.0);
        /* %.12g in the table: the closed form to 12 digits. */
        assert_close(tsv_number(tsv, file, "mean_recurrence"), period, 0.0, 2e-11 * period);
        assert_close(tsv_number(tsv, file, "peak_slip_rate"), peak, 0.0, 2e-11 * peak);
        assert_close(tsv_number(tsv, file, "run.t_end"), 8.0, 0.0, 0.0);
        assert_close(tsv_number(tsv, file, "t_reached"), 8.0, 0.0, 0.0);
        assert_close(tsv_number(tsv, file, "largest_event_blocks"), 1.0, 0.0, 0.0);
        assert_close(tsv_number(tsv, file, "seed"), 1.0, 0.0, 0.0);
        /* All events of one block are alike: no b-value. */
        assert_true(isnan(tsv_number(tsv, file, "b_value")));
        assert_string_equal(tsv_field(tsv, file, header_column(tsv, "point")), k ? "p1" : "p0");
        assert_string_equal(tsv_field(tsv, file, header_column(tsv, "catalog")), "ruptures");
    }
    double period_0, peak_0;
    closed_form(0.1, &period_0, &peak_0);
    double sampled = tsv_number(tsv, "mu_2.h5", "peak_slip_rate");
    assert_true(sampled <= peak_0 * (1.0 + 1e-12) && sampled >= 0.999 * peak_0);
    assert_true(isnan(tsv_number(tsv, "mu_2.h5", "events")));
    assert_true(isnan(tsv_number(tsv, "mu_2.h5", "mean_recurrence")));
    assert_string_equal(tsv_field(tsv, "mu_2.h5", header_column(tsv, "catalog")), "-");
    /* A text key: set in one run only; "-" where a run did not set it. */
    assert_string_equal(tsv_field(tsv, "mu_0.h5", header_column(tsv, "solver.method")), "-");
    assert_string_equal(tsv_field(tsv, "mu_1.h5", header_column(tsv, "solver.method")), "exact");
    assert_string_equal(tsv_field(tsv, "mu_1.h5", header_column(tsv, "method")), "exact");

    /* The HDF5 table: the same rows, numeric key columns as doubles, units per column. */
    char h5[600];
    snprintf(h5, sizeof h5, "%s/summary.h5", dir);
    hid_t file = H5Fopen(h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t dset = H5Dopen2(file, "summary", H5P_DEFAULT);
    assert_true(dset >= 0);
    char *units = attr_string(dset, "units");
    assert_non_null(strstr(units, "friction.mu_d: 1"));
    assert_non_null(strstr(units, "mean_recurrence: s"));
    assert_non_null(strstr(units, "peak_slip_rate: m/s"));
    free(units);
    hid_t mem = H5Tcreate(H5T_COMPOUND, 2 * sizeof(double));
    H5Tinsert(mem, "friction.mu_d", 0, H5T_NATIVE_DOUBLE);
    H5Tinsert(mem, "mean_recurrence", sizeof(double), H5T_NATIVE_DOUBLE);
    double rows[3][2];
    assert_true(H5Dread(dset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) >= 0);
    /* In the grid's order: mu_2 (mu_d = 0.1 too) sorts after mu_0, which sets no
     * output.events, and before mu_1 (0.3). */
    for (int k = 0; k < 2; ++k) {
        double period, peak;
        closed_form(mu_d[k], &period, &peak);
        assert_close(rows[2 * k][0], mu_d[k], 0.0, 0.0);
        assert_close(rows[2 * k][1], period, 0.0, 1e-12 * period);
    }
    H5Tclose(mem);
    H5Dclose(dset);
    H5Fclose(file);
}

/* The figures a summary row should hold for the complete rows of a catalog in [t_from, t_to). */
typedef struct expected {
    double events, mean_recurrence, largest_magnitude, largest_blocks, peak;
} expected;

static void expect_row(expected *e, size_t n, const double *t_start, const double *magnitude,
                       const int32_t *n_blocks, const double *max_slip_rate, const int8_t *complete)
{
    double first = INFINITY, last = -INFINITY;
    *e = (expected){0.0, NAN, -INFINITY, NAN, -INFINITY};
    for (size_t i = 0; i < n; ++i) {
        if (!complete[i])
            continue;
        e->events += 1.0;
        first = fmin(first, t_start[i]);
        last = fmax(last, t_start[i]);
        if (magnitude[i] > e->largest_magnitude) {
            e->largest_magnitude = magnitude[i];
            e->largest_blocks = n_blocks[i];
        }
        e->peak = fmax(e->peak, max_slip_rate[i]);
    }
    e->mean_recurrence = (last - first) / (e->events - 1.0);
}

static void check_row(const char *tsv, const char *file, const char *catalog, const expected *e)
{
    assert_string_equal(tsv_field(tsv, file, header_column(tsv, "catalog")), catalog);
    assert_close(tsv_number(tsv, file, "events"), e->events, 0.0, 0.0);
    assert_close(tsv_number(tsv, file, "mean_recurrence"), e->mean_recurrence, 1e-11, 0.0);
    assert_close(tsv_number(tsv, file, "largest_magnitude"), e->largest_magnitude, 1e-11, 0.0);
    assert_close(tsv_number(tsv, file, "largest_event_blocks"), e->largest_blocks, 0.0, 0.0);
    assert_close(tsv_number(tsv, file, "peak_slip_rate"), e->peak, 1e-11, 0.0);
}

/* bk_h5_summary into dir with table, notes to a file; returns its status, the notes in *text. */
static int summarise_dir(const char *dir, const char *table, size_t *runs, char **text, bk_error *err)
{
    char notes_path[600], cmd[700];
    snprintf(notes_path, sizeof notes_path, "%s/notes.txt", tmpdir);
    FILE *notes = fopen(notes_path, "w");
    assert_non_null(notes);
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    int rc = bk_h5_summary(dir, table, &opt, notes, runs, err);
    fclose(notes);
    snprintf(cmd, sizeof cmd, "cat %s", notes_path);
    assert_int_equal(run_command(cmd, text), 0);
    return rc;
}

/* A ring of 100 blocks, whose 20-odd events hold 200-odd ruptures: by default every catalog
 * figure is the ruptures'; --table events gives the events'; a run without /ruptures (as
 * written before there were ruptures) falls back to /events, and says so; a run without a
 * table named is left out. */
static void test_catalog_table(void **state)
{
    (void)state;
    char dir[300], cmd[4096], ring[400], old[400], tsv[400];
    snprintf(dir, sizeof dir, "%s/ring", tmpdir);
    snprintf(ring, sizeof ring, "%s/ring.h5", dir);
    snprintf(old, sizeof old, "%s/old.h5", dir);
    snprintf(tsv, sizeof tsv, "%s/summary.tsv", dir);
    snprintf(cmd, sizeof cmd, "./bksim run configs/chains/carlson_langer_100.ini -q -o %s --set run.t_end=150 "
             "&& cp %s %s", ring, ring, old);
    assert_int_equal(run_command(cmd, NULL), 0);
    /* As a file from before the rupture catalog: none of its tables, none in the list of
     * datasets written (a file that lists a table it lacks is damaged, and left out). */
    hid_t file = H5Fopen(old, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_true(H5Ldelete(file, "ruptures", H5P_DEFAULT) >= 0);
    assert_true(H5Ldelete(file, "rupture_blocks", H5P_DEFAULT) >= 0);
    assert_true(H5Ldelete(file, "rupture_rate", H5P_DEFAULT) >= 0);
    assert_true(H5Adelete(file, "datasets") >= 0);
    H5Fclose(file);
    assert_int_equal(bk_h5_verify(old, &(bk_error){0}), BK_OK);

    bk_error err = {0};
    bk_rupture *ruptures = NULL;
    bk_event *events = NULL;
    size_t n_ruptures = 0, n_events = 0;
    assert_int_equal(bk_h5_read_ruptures(ring, &ruptures, &n_ruptures, &err), BK_OK);
    assert_int_equal(bk_h5_read_events(ring, &events, &n_events, &err), BK_OK);
    double *t = malloc((n_ruptures + n_events) * sizeof *t), *m = malloc((n_ruptures + n_events) * sizeof *m);
    double *v = malloc((n_ruptures + n_events) * sizeof *v);
    int32_t *b = malloc((n_ruptures + n_events) * sizeof *b);
    int8_t *c = malloc(n_ruptures + n_events);
    assert_true(t && m && v && b && c);
    for (size_t i = 0; i < n_ruptures; ++i)
        t[i] = ruptures[i].t_start, m[i] = ruptures[i].magnitude, b[i] = ruptures[i].n_blocks,
        v[i] = ruptures[i].max_slip_rate, c[i] = ruptures[i].complete;
    expected from_ruptures, from_events;
    expect_row(&from_ruptures, n_ruptures, t, m, b, v, c);
    for (size_t i = 0; i < n_events; ++i)
        t[i] = events[i].t_start, m[i] = events[i].magnitude, b[i] = events[i].n_blocks,
        v[i] = events[i].max_slip_rate, c[i] = events[i].complete;
    expect_row(&from_events, n_events, t, m, b, v, c);
    free(t), free(m), free(v), free(b), free(c);
    free(ruptures);
    free(events);
    /* The two catalogs differ, so the figures say which was read. */
    assert_true(from_events.events >= 10.0 && from_ruptures.events > 3.0 * from_events.events);

    /* Default: the ruptures, and for old.h5 its /events, said once on the notes. */
    size_t runs = 0;
    char *text = NULL;
    assert_int_equal(summarise_dir(dir, NULL, &runs, &text, &err), BK_OK);
    assert_int_equal(runs, 2);
    assert_non_null(strstr(text, "1 of 2 runs have no /ruptures table: their catalog figures are from /events"));
    free(text);
    check_row(tsv, "ring.h5", "ruptures", &from_ruptures);
    check_row(tsv, "old.h5", "events", &from_events);
    /* The b-value is `bksim stats`'s of the same table: this ring's 43 magnitudes above Mc
     * fail the Gutenberg-Richter fit test, so neither gives one. */
    bk_stats_report *report = NULL;
    assert_int_equal(bk_stats_report_read(ring, NULL, NULL, &report, &err), BK_OK);
    assert_false(report->have_b);
    assert_non_null(strstr(report->b_note, "are not Gutenberg-Richter distributed"));
    assert_true(isnan(tsv_number(tsv, "ring.h5", "b_value")));
    assert_true(isnan(tsv_number(tsv, "ring.h5", "b_events")));
    bk_stats_report_free(report);

    /* --table events: the events of both, no fallback to tell. */
    assert_int_equal(summarise_dir(dir, "events", &runs, &text, &err), BK_OK);
    assert_int_equal(runs, 2);
    assert_null(strstr(text, "no /ruptures"));
    free(text);
    check_row(tsv, "ring.h5", "events", &from_events);
    check_row(tsv, "old.h5", "events", &from_events);

    /* --table ruptures: old.h5 has none and is left out, named with the table. */
    assert_int_equal(summarise_dir(dir, "/ruptures", &runs, &text, &err), BK_OK);
    assert_int_equal(runs, 1);
    assert_non_null(strstr(text, "old.h5: no /ruptures table (--table ruptures)"));
    free(text);
    check_row(tsv, "ring.h5", "ruptures", &from_ruptures);

    /* A table no run has: nothing to summarise, an error naming it; on the command line, exit 1. */
    assert_int_equal(summarise_dir(dir, "rupture_catalog", &runs, &text, &err), BK_ERR_INVALID);
    assert_non_null(strstr(text, "ring.h5: no /rupture_catalog table"));
    free(text);
    assert_non_null(strstr(err.message, dir));
    assert_non_null(strstr(err.message, "with a /rupture_catalog table"));
    snprintf(cmd, sizeof cmd, "./bksim summary %s --table rupture_catalog", dir);
    expect_command(cmd, 1, "old.h5: no /rupture_catalog table");
    snprintf(cmd, sizeof cmd, "./bksim summary %s --table=events", dir);
    expect_command(cmd, 0, "2 runs");
    assert_string_equal(tsv_field(tsv, "ring.h5", header_column(tsv, "catalog")), "events");
    snprintf(cmd, sizeof cmd, "./bksim summary %s", dir);
    expect_command(cmd, 0, "their catalog figures are from /events");
    assert_string_equal(tsv_field(tsv, "ring.h5", header_column(tsv, "catalog")), "ruptures");
    snprintf(cmd, sizeof cmd, "./bksim summary %s --table", dir);
    expect_command(cmd, 2, "unknown or incomplete option '--table'");
    snprintf(cmd, sizeof cmd, "./bksim summary %s --table=", dir);
    expect_command(cmd, 2, "--table needs a table name");
    expect_command("./bksim summary --help", 0, "--table NAME");
}

static void test_nothing_to_summarise(void **state)
{
    (void)state;
    char dir[512];
    snprintf(dir, sizeof dir, "%s/empty", tmpdir);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
    assert_int_equal(run_command(cmd, NULL), 0);
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    bk_error err = {0};
    assert_int_equal(bk_h5_summary(dir, NULL, &opt, NULL, NULL, &err), BK_ERR_INVALID);
    assert_non_null(strstr(err.message, "no finished bksim output"));
    char path[600];
    snprintf(path, sizeof path, "%s/summary.tsv", dir);
    assert_false(path_exists(path));
    snprintf(path, sizeof path, "%s/none", tmpdir);
    assert_int_equal(bk_h5_summary(path, NULL, &opt, NULL, NULL, &err), BK_ERR_IO);
    assert_non_null(strstr(err.message, "cannot read the directory"));
    /* The command line: exit 1 with the message; bad options exit 2. */
    snprintf(cmd, sizeof cmd, "./bksim summary %s", dir);
    expect_command(cmd, 1, "no finished bksim output");
    expect_command("./bksim summary", 2, "missing DIR");
    snprintf(cmd, sizeof cmd, "./bksim summary %s --bin 0", dir);
    expect_command(cmd, 2, "magnitude bin width 0");
    snprintf(cmd, sizeof cmd, "./bksim summary %s --from x", dir);
    expect_command(cmd, 2, "--from needs a time");
}

/* Rows in the grid's order (1e-3 m/s after 5e-4: file names would put it first), and a
 * finished file whose dataset was cut short left out and named instead of summarised. */
static void test_grid_order_and_damage(void **state)
{
    (void)state;
    char dir[512], cmd[2048];
    snprintf(dir, sizeof dir, "%s/grid", tmpdir);
    const char *values[] = {"1e-3", "5e-4", "2e-3"};
    for (size_t k = 0; k < 3; ++k) {
        snprintf(cmd, sizeof cmd, "./bksim run configs/paper/case_a_coulomb.ini -q -o %s/driver.velocity=%s.h5 "
                 "--set driver.velocity=%s --set run.t_end=1", dir, values[k], values[k]);
        assert_int_equal(run_command(cmd, NULL), 0);
    }
    snprintf(cmd, sizeof cmd, "cp %s/driver.velocity=1e-3.h5 %s/damaged.h5", dir, dir);
    assert_int_equal(run_command(cmd, NULL), 0);
    char damaged[600];
    snprintf(damaged, sizeof damaged, "%s/damaged.h5", dir);
    hid_t file = H5Fopen(damaged, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t v = H5Dopen2(file, "v", H5P_DEFAULT);
    hsize_t dims[2] = {100, 1};
    assert_true(H5Dset_extent(v, dims) >= 0);
    H5Dclose(v);
    H5Fclose(file);
    bk_stats_options opt;
    bk_stats_options_default(&opt);
    bk_error err = {0};
    char *notes_text = NULL;
    size_t notes_len = 0, n_runs = 0;
    FILE *notes = open_memstream(&notes_text, &notes_len);
    assert_int_equal(bk_h5_summary(dir, NULL, &opt, notes, &n_runs, &err), BK_OK);
    fclose(notes);
    assert_int_equal(n_runs, 3);
    assert_non_null(strstr(notes_text, "left out "));
    assert_non_null(strstr(notes_text, "damaged.h5: damaged: /v has 100 rows"));
    free(notes_text);
    snprintf(cmd, sizeof cmd, "awk -F'\\t' '!/^#/ && NR > 2 {print $1}' %s/summary.tsv | tr '\\n' ' '", dir);
    char *order = NULL;
    assert_int_equal(run_command(cmd, &order), 0);
    assert_string_equal(order, "driver.velocity=5e-4.h5 driver.velocity=1e-3.h5 driver.velocity=2e-3.h5 ");
    free(order);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_figures_and_columns),
        cmocka_unit_test(test_catalog_table),
        cmocka_unit_test(test_nothing_to_summarise),
        cmocka_unit_test(test_grid_order_and_damage),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
